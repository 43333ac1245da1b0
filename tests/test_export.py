"""Exports for other tools (--aligned, --transform, --distances, --plot by extension), with
known answers: maps made from a plan with a known transform, exported, read back."""

from __future__ import annotations

import json

import numpy as np
import open3d as o3d
import pytest
import yaml
from scipy.spatial.distance import cdist

from pcmapq.core.frames import Frames, Levelling
from pcmapq.core.transform import Similarity2D
from pcmapq.io import load_map
from pcmapq.io.export import DISTANCE_FIELD, record_dtype, records, write_matrix, write_records
from pcmapq.report.export import cloud_matrix, colours
from pcmapq.report.plot import figure_bytes
from pcmapq.testing import synth

from .conftest import PLAN, in_map_frame, write_image_map
from .test_cli import run

#: The known map -> truth transform of these tests: p_truth = R(25 deg) p_map + (3, -2).
KNOWN = Similarity2D(3.0, -2.0, float(np.radians(25.0)))


def rotation_about(axis: np.ndarray, degrees: float) -> np.ndarray:
    """3x3 rotation about a unit axis."""
    return o3d.geometry.get_rotation_matrix_from_axis_angle(
        np.asarray(axis, dtype=np.float64) * np.radians(degrees))


def read_cloud(path) -> dict[str, np.ndarray]:
    """A PLY/PCD's attributes as NumPy arrays, read by Open3D."""
    cloud = o3d.t.io.read_point_cloud(str(path))
    return {key: cloud.point[key].numpy() for key in cloud.point}


# --- formats -----------------------------------------------------------------------------------

@pytest.mark.parametrize("suffix", [".ply", ".pcd"])
def test_clouds_read_back_by_open3d(suffix, tmp_path):
    """Chunks of float32 points written as PLY or PCD: Open3D reads the same points."""
    rng = np.random.default_rng(0)
    xyz = rng.uniform(-50, 50, size=(1001, 3))
    dtype = record_dtype()
    write_records(tmp_path / f"c{suffix}", len(xyz),
                  (records(part, dtype) for part in np.array_split(xyz, 3)), dtype, "test")
    np.testing.assert_array_equal(read_cloud(tmp_path / f"c{suffix}")["positions"],
                                  xyz.astype(np.float32))


def test_distance_cloud_has_a_scalar_field_and_colours(tmp_path):
    xyz = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    distance = np.array([0.0, 0.25, 7.0])
    dtype = record_dtype(DISTANCE_FIELD, colour=True)
    write_records(tmp_path / "d.ply", 3, [records(xyz, dtype, distance,
                                                  colours(distance, 0.5))], dtype)
    back = read_cloud(tmp_path / "d.ply")
    np.testing.assert_array_equal(back[DISTANCE_FIELD].ravel(), distance.astype(np.float32))
    # viridis: dark blue at 0 m, yellow from the clip (0.5 m) on, a middle colour between
    assert back["colors"].tolist()[0] == [68, 1, 84] and back["colors"].tolist()[2][0] > 200
    assert len({tuple(c) for c in back["colors"].tolist()}) == 3


def test_a_cloud_with_a_scalar_field_is_not_written_as_pcd(tmp_path):
    from pcmapq.core.errors import InputError

    dtype = record_dtype(DISTANCE_FIELD)
    with pytest.raises(InputError, match="d.pcd: a cloud with a scalar field"):
        write_records(tmp_path / "d.pcd", 0, [], dtype)
    assert list(tmp_path.iterdir()) == []


def test_matrix_reads_back_exactly(tmp_path):
    m = np.eye(4)
    m[:3, :3] = rotation_about([0.3, 0.4, np.sqrt(0.75)], 33.3)
    m[:3, 3] = [1 / 3, -2e-7, 123.456]
    write_matrix(tmp_path / "T.txt", m)
    np.testing.assert_array_equal(np.loadtxt(tmp_path / "T.txt"), m)
    assert len((tmp_path / "T.txt").read_text().splitlines()) == 4


@pytest.mark.parametrize("suffix,magic", [(".png", b"\x89PNG"), (".svg", b"<?xml"),
                                          (".pdf", b"%PDF")])
def test_figures_by_extension_and_the_same_every_time(suffix, magic, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    def drawn() -> bytes:
        fig = Figure()
        fig.add_subplot().plot([0, 1, 2], [1, 0, 1])
        return figure_bytes(fig, suffix[1:], 50)

    first = drawn()
    assert first.startswith(magic) and first == drawn()


# --- the transform chain -------------------------------------------------------------------------

def test_cloud_matrix_composes_the_chain():
    """A 3D truth cloud tilted by 4 degrees with its floor at z = 1.5 m, a map cloud tilted
    otherwise, floor at -0.7 m, turned and shifted: the chain takes map points onto the truth
    points they came from."""
    rng = np.random.default_rng(1)
    plan_points = np.column_stack([rng.uniform(0, 20, (50, 2)), rng.uniform(0, 3, 50)])
    tilt_t, tilt_m = rotation_about([1, 0, 0], 4.0), rotation_about([0.6, 0.8, 0], 3.0)
    # truth cloud: levelled by tilt_t, floor at 1.5 m; map cloud: levelled by tilt_m, floor -0.7
    truth = (plan_points + [0, 0, 1.5]) @ tilt_t          # tilt_t.T applied: levelling undoes it
    in_map_plan = np.column_stack([KNOWN.inverse().apply(plan_points[:, :2]),
                                   plan_points[:, 2] - 0.7])
    cloud = in_map_plan @ tilt_m
    frames = Frames(KNOWN, Levelling(tilt_m, -0.7), Levelling(tilt_t, 1.5))
    m = cloud_matrix(frames)
    np.testing.assert_allclose(cloud @ m[:3, :3].T + m[:3, 3], truth, atol=1e-9)


def test_after_a_3d_registration_the_chain_is_the_registration():
    reg = np.eye(4)
    reg[:3, :3], reg[:3, 3] = rotation_about([0.1, 0.2, 0.97], 40.0), [5.0, -3.0, 0.4]
    frames = Frames(Similarity2D(), Levelling(rotation_about([1, 0, 0], 2.0), 0.3),
                    Levelling(rotation_about([0, 1, 0], 1.0), -0.2), reg)
    np.testing.assert_allclose(cloud_matrix(frames), reg, atol=1e-12)


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
