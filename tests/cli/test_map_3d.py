"""MapEval's AWD and SCS through ``pcmapq eval`` on two 3D clouds: in the frame given
(``--no-align``) they are the plain reference's on the files' points; after a 3D registration,
those of the map in the truth's frame, whether the registration searched or started where
``--init-3d`` says."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pcmapq.io.export import write_matrix
from testkit import synth
from testkit.command import run
from testkit.mapeval import reference_awd_scs
from testkit.poses import rotation_about

PLAN = synth.building_plan(0)


@pytest.fixture(scope="module")
def clouds(tmp_path_factory) -> tuple[Path, np.ndarray, np.ndarray]:
    """A 3D cloud of the plan (the truth) and a noisier one with a wall moved 0.3 m (the map),
    in one frame, as .npy files."""
    folder = tmp_path_factory.mktemp("map3d")
    truth = synth.lidar_cloud(PLAN, spacing=0.1, noise=0.005, outliers=0)
    cloud = synth.lidar_cloud(synth.move_wall(PLAN, 7, (0.3, 0.0)), spacing=0.1, noise=0.01,
                              outliers=0, seed=1)
    np.save(folder / "truth.npy", truth)
    np.save(folder / "map.npy", cloud)
    return folder, cloud, truth


def evaluate(folder: Path, map_name: str, *options: str) -> tuple[dict, str]:
    out = folder / f"{map_name}{len(options)}.json"
    proc = run("eval", str(folder / map_name), str(folder / "truth.npy"), "--json", str(out),
               *options)
    assert proc.returncode == 0, proc.stderr
    return json.loads(out.read_text()), proc.stdout


@pytest.mark.parametrize("settings", [(3.0, 100, 5), (1.5, 20, 2)])
def test_in_the_frame_given_the_figures_are_the_references(clouds, settings):
    folder, cloud, truth = clouds
    voxel, min_points, radius = settings
    options = ("--awd-voxel", f"{voxel:g}", "--awd-min-points", str(min_points),
               "--scs-radius", str(radius))
    doc, stdout = evaluate(folder, "map.npy", "--no-align",
                           *(options if settings != (3.0, 100, 5) else ()))
    awd, scs, voxels = reference_awd_scs(cloud, truth, voxel, min_points, radius)
    got = doc["map_3d"]
    assert got["voxels"] == voxels > 20
    assert got["awd_m"] == pytest.approx(awd, abs=1e-6)  # the JSON keeps 6 decimals
    assert got["scs"] == pytest.approx(scs, abs=1e-6)
    assert doc["settings"]["map_3d"] == {**doc["settings"]["map_3d"], "voxel": voxel,
                                         "min_points": min_points,
                                         "radius": radius}
    assert f"{voxel:g} m voxels holding at least {min_points} points" in got["computed_on"]
    assert "alignment_3d" not in doc and "distances_3d" not in doc  # no 3D registration
    assert f"AWD {awd:.3f} m" in stdout and f"SCS {scs:.3f}" in stdout


def test_after_a_3d_registration_the_figures_are_the_maps_in_the_truths_frame(clouds):
    """The map turned 30 degrees and moved: registered, its figures are within a centimetre
    of those of the map given in the truth's frame."""
    folder, cloud, truth = clouds
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation_about([0, 0, 1], 30.0), [2.0, -1.0, 0.0]
    np.save(folder / "moved.npy", cloud @ pose[:3, :3].T + pose[:3, 3])
    doc, _ = evaluate(folder, "moved.npy", "--fail-over", "awd_3d=1")
    awd, scs, voxels = reference_awd_scs(cloud, truth)
    assert doc["alignment_3d"] is not None
    assert doc["map_3d"]["awd_m"] == pytest.approx(awd, abs=0.01)
    assert doc["map_3d"]["voxels"] == pytest.approx(voxels, abs=2)
    assert doc["gates"] == [{"key": "awd_3d", "path": "map_3d.awd_m", "option": "--fail-over",
                             "bound": 1.0, "value": doc["map_3d"]["awd_m"], "passed": True}]


def test_a_3d_start_is_where_the_registration_begins(clouds):
    """``--init-3d``: the map turned 30 degrees and moved, started 2 degrees and 0.2 m off
    its pose (a file as ``--transform`` writes it) or at the identity, is registered where
    the global search registers it, with every 3D figure; started 90 degrees off, its ICP
    stays in another pose (no global search ran) that hangs off the truth: refused in one line
    naming the start, and forced, fitness under 0.2."""
    folder, cloud, _ = clouds
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation_about([0, 0, 1], 30.0), [2.0, -1.0, 0.0]
    np.save(folder / "turned.npy", cloud @ pose[:3, :3].T + pose[:3, 3])
    back = np.linalg.inv(pose)
    near, far = np.eye(4), np.eye(4)
    near[:3, :3], near[:3, 3] = rotation_about([0, 0, 1], 2.0), [0.2, -0.1, 0.05]
    far[:3, :3] = rotation_about([0, 0, 1], 90.0)
    write_matrix(folder / "near.txt", near @ back)
    write_matrix(folder / "far.txt", far @ back)
    searched, _ = evaluate(folder, "turned.npy", "--no-noref")
    want = np.array(searched["alignment_3d"]["matrix"])
    assert np.abs(want[:3, 3] - back[:3, 3]).max() < 0.01
    for start in (str(folder / "near.txt"), "identity"):
        doc, stdout = evaluate(folder, "turned.npy", "--no-noref", "--init-3d", start)
        np.testing.assert_allclose(doc["alignment_3d"]["matrix"], want, atol=1e-4)
        assert doc["map_3d"]["awd_m"] == pytest.approx(searched["map_3d"]["awd_m"], abs=1e-3)
        assert doc["structures_3d"]["planes"]["f1"] == searched["structures_3d"]["planes"]["f1"]
        assert len(doc["settings"]["alignment"]["init_3d"]) == 16
        assert doc["alignment"]["method"] == "3d+init" != searched["alignment"]["method"]
        assert "registered in 3D from --init-3d" in " ".join(stdout.split())
    again, _ = evaluate(folder, "turned.npy", "--no-noref", "--init-3d", str(folder / "near.txt"))
    first, _ = evaluate(folder, "turned.npy", "--no-noref", "--init-3d", str(folder / "near.txt"))
    assert json.dumps(again) == json.dumps(first)  # the same command, the same result
    refused = run("eval", str(folder / "turned.npy"), str(folder / "truth.npy"), "--no-noref",
                  "--init-3d", str(folder / "far.txt"))
    assert refused.returncode == 1 and refused.stderr.count("\n") == 1, refused.stderr
    assert "the given frame" in refused.stderr and "--init-3d" in refused.stderr
    doc, _ = evaluate(folder, "turned.npy", "--no-noref", "--force", "--init-3d",
                      str(folder / "far.txt"))
    assert doc["alignment_3d"]["fitness"] < 0.2 < searched["alignment_3d"]["fitness"]
    assert doc["alignment"]["verdict"] == "another place"


def test_a_3d_start_with_a_plan_is_refused_in_one_line(clouds, tmp_path):
    """An image or a 2D cloud on either side has no 3D registration to start: exit 2, one line
    naming the side."""
    folder, _, truth = clouds
    flat = tmp_path / "flat.npy"
    np.save(flat, truth[:, :2])
    proc = run("eval", str(flat), str(folder / "truth.npy"), "--init-3d", "identity")
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert f"{flat} is not a 3D cloud" in proc.stderr and "Traceback" not in proc.stderr
