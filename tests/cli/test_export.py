"""Exports for other tools (--aligned, --transform, --distances, --plot by extension), with
known answers: maps made from a plan with a known transform, exported, read back."""

from __future__ import annotations

import json

import numpy as np
import yaml
from scipy.spatial.distance import cdist

from pcmapq.core.transform import Similarity2D
from pcmapq.io import load_map
from pcmapq.io.export import DISTANCE_FIELD
from testkit import synth
from testkit.command import run
from testkit.files import in_map_frame, read_cloud, write_image_map
from testkit.poses import rotation_about

#: The known map -> truth transform of these tests: p_truth = R(25 deg) p_map + (3, -2).
#: The plan of the exports' maps.
PLAN = synth.building_plan(0)
KNOWN = Similarity2D(3.0, -2.0, float(np.radians(25.0)))


# --- through the command line, known answers ----------------------------------------------------

def test_2d_cloud_exports(tmp_path):
    """A 2D cloud of the plan with one wall moved 0.3 m, in a map frame KNOWN away: the aligned
    cloud lies on the plan, the 3x3 matrix is KNOWN and gives the aligned points; the distance
    cloud holds the cells the accuracy counts (within a cell of the aligned points), each with
    its distance to the truth (0.3 m on the moved wall), and their statistics are the JSON's
    accuracy."""
    truth = synth.wall_points(PLAN, spacing=0.05)
    moved = synth.move_wall(PLAN, 7, (0.3, 0.0))
    in_plan = synth.wall_points(moved, spacing=0.05)
    np.save(tmp_path / "truth.npy", truth)
    np.save(tmp_path / "map.npy", KNOWN.inverse().apply(in_plan))
    out = {name: tmp_path / name for name in ("a.ply", "T.txt", "d.ply")}
    proc = run("eval", str(tmp_path / "map.npy"), str(tmp_path / "truth.npy"),
               "--aligned", str(out["a.ply"]), "--transform", str(out["T.txt"]),
               "--distances", str(out["d.ply"]), "--json", str(tmp_path / "r.json"))
    assert proc.returncode == 0, proc.stderr
    assert all(f"wrote {p}" in proc.stderr for p in out.values())
    matrix = np.loadtxt(out["T.txt"])
    assert matrix.shape == (4, 4)  # as CloudCompare applies it
    np.testing.assert_allclose(matrix[[0, 1, 3]][:, [0, 1, 3]], KNOWN.matrix, atol=0.01)
    np.testing.assert_allclose(matrix[2], [0.0, 0.0, 1.0, 0.0], atol=1e-12)
    aligned = read_cloud(out["a.ply"])["positions"]
    map_xy = np.load(tmp_path / "map.npy")
    np.testing.assert_allclose(aligned[:, :2], map_xy @ matrix[:2, :2].T + matrix[:2, 3],
                               atol=1e-5)
    assert np.abs(aligned[:, 2]).max() == 0.0
    assert np.abs(aligned[:, :2] - in_plan).max() < 0.02
    back = read_cloud(out["d.ply"])
    xy, got = back["positions"][:, :2].astype(np.float64), back[DISTANCE_FIELD].ravel()
    assert np.abs(back["positions"][:, 2]).max() == 0.0
    assert cdist(xy, aligned[:, :2]).min(axis=1).max() < 0.05
    np.testing.assert_allclose(got, cdist(xy, truth).min(axis=1), atol=0.05)
    assert 0.27 < got.max() < 0.33 and np.median(got) < 0.03
    assert_reproduces(got, json.loads((tmp_path / "r.json").read_text())["distances"])


def assert_reproduces(distances: np.ndarray, block: dict) -> None:
    """The statistics of a --distances file's distances are the JSON's accuracy, to 1e-6."""
    from pcmapq.core.stats import Stats

    want, got = block["accuracy_m"], Stats.of(distances).to_dict()
    assert got["count"] == want["count"]
    for key in ("mean", "median", "rmse", "std", "min", "max", "p95"):
        assert abs(got[key] - want[key]) <= 1e-6, (key, got[key], want[key])


def test_3d_cloud_exports(truth_png, tmp_path):
    """A 3D cloud of the plan (floor at z = 0) tilted by 2 degrees, turned, shifted and lifted
    by 0.8 m, against the plan's image: the 4x4 matrix takes the map's points to the aligned
    ones, which lie where the plan has them, z the height above the floor."""
    cloud = synth.lidar_cloud(PLAN, spacing=0.1, noise=0.005, outliers=0)
    pose = np.eye(4)
    pose[:3, :3] = rotation_about([0, 0, 1], -25.0) @ rotation_about([1, 1, 0] / np.sqrt(2), 2.0)
    pose[:3, 3] = [-4.0, 1.0, 0.8]
    np.save(tmp_path / "map.npy", cloud @ pose[:3, :3].T + pose[:3, 3])
    a, t, d = tmp_path / "a.pcd", tmp_path / "T.txt", tmp_path / "d.ply"
    proc = run("eval", str(tmp_path / "map.npy"), str(truth_png), "--aligned", str(a),
               "--transform", str(t), "--distances", str(d), "--json", str(tmp_path / "r.json"))
    assert proc.returncode == 0, proc.stderr
    matrix = np.loadtxt(t)
    assert matrix.shape == (4, 4)
    aligned = read_cloud(a)["positions"].astype(np.float64)
    source = np.load(tmp_path / "map.npy")
    np.testing.assert_allclose(aligned, source @ matrix[:3, :3].T + matrix[:3, 3], atol=1e-4)
    np.testing.assert_allclose(aligned, cloud, atol=0.03)
    # the distance cloud: the plan cells of the wall band the accuracy counts, on the floor
    band = read_cloud(d)
    assert np.abs(band["positions"][:, 2]).max() == 0.0
    assert np.percentile(band[DISTANCE_FIELD], 95) < 0.06
    assert_reproduces(band[DISTANCE_FIELD].ravel(),
                      json.loads((tmp_path / "r.json").read_text())["distances"])


def test_3d_pair_distances_reproduce_the_3d_accuracy(tmp_path):
    """Two 3D clouds of the plan, the map with one wall moved 0.3 m and turned and shifted: the
    distance cloud holds the map's voxel centroids the 3D accuracy counts, and their statistics
    are the JSON's ``distances_3d.accuracy_m``; the JSON says what each block is computed on."""
    truth = synth.lidar_cloud(PLAN, spacing=0.1, noise=0.005, outliers=0)
    cloud = synth.lidar_cloud(synth.move_wall(PLAN, 7, (0.3, 0.0)), spacing=0.1, noise=0.005,
                              outliers=0)
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation_about([0, 0, 1], 30.0), [2.0, -1.0, 0.0]
    np.save(tmp_path / "truth.npy", truth)
    np.save(tmp_path / "map.npy", cloud @ pose[:3, :3].T + pose[:3, 3])
    d = tmp_path / "d.ply"
    proc = run("eval", str(tmp_path / "map.npy"), str(tmp_path / "truth.npy"), "--distances",
               str(d), "--json", str(tmp_path / "r.json"))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "r.json").read_text())
    back = read_cloud(d)[DISTANCE_FIELD].ravel()
    assert_reproduces(back, doc["distances_3d"])
    assert 0.25 < back.max() < 0.35
    assert "3D" in doc["distances_3d"]["computed_on"]
    assert "plan" in doc["distances"]["computed_on"]
    assert "wall band" in doc["distances"]["computed_on"]


def test_image_map_exports(truth_png, tmp_path):
    """The plan drawn in a map frame KNOWN away: the aligned image, read back through its
    map_server YAML, has its walls on the truth's walls, on the truth's cell lattice."""
    map_png = write_image_map(in_map_frame(PLAN, KNOWN), tmp_path / "map.png")
    aligned, t = tmp_path / "aligned.png", tmp_path / "T.txt"
    proc = run("eval", str(map_png), str(truth_png), "--aligned", str(aligned),
               "--transform", str(t))
    assert proc.returncode == 0, proc.stderr
    assert f"wrote {aligned.with_suffix('.yaml')}" in proc.stderr
    matrix = np.loadtxt(t)
    np.testing.assert_allclose(matrix[[0, 1, 3]][:, [0, 1, 3]], KNOWN.matrix, atol=0.025)
    doc = yaml.safe_load(aligned.with_suffix(".yaml").read_text())
    assert doc["image"] == "aligned.png" and doc["origin"][2] == 0.0
    back, truth = load_map(aligned.with_suffix(".yaml")), load_map(truth_png)
    assert back.grid.resolution == truth.grid.resolution
    offset = (np.array(back.grid.origin[:2]) - truth.grid.origin[:2]) / truth.grid.resolution
    np.testing.assert_allclose(offset, np.round(offset), atol=1e-6)
    walls = back.grid.cell_centres(back.state == 1)
    truth_walls = truth.grid.cell_centres(truth.state == 1)
    near = cdist(walls, truth_walls).min(axis=1)
    assert np.mean(near <= 0.05 + 1e-9) > 0.97 and near.max() < 0.2
