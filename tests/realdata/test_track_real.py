"""`pcmapq track` on real runs. KITTI's reference poses, which are the left camera's, are read
through ``--calib`` as `pcmapq map` does: the pose errors are those of the LiDAR frame the run
is in, checked against figures computed here from the poses alone. A CARMEN log scored against
itself ends at 1."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.io.writers import write_cloud
from pcmapq.mapping import build_map_from_poses, open_scans, read_poses, write_kitti_poses
from testkit.paths import shared

#: KITTI odometry sequence 00's Tr (velodyne -> left camera), row-major 3x4
#: (../shared/README.md).
TR = np.array([4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03,
               -1.198459927713e-02, -7.210626507497e-03, 8.081198471645e-03,
               -9.999413164504e-01, -5.403984729748e-02, 9.999738645903e-01,
               4.859485810390e-04, -7.206933692422e-03, -2.921968648686e-01])
#: Scans of the run, scored every EVERY.
SCANS, EVERY = 6, 3
#: The estimate's known error: each LiDAR step's translation GAIN longer, turned YAW_DEG more.
GAIN, YAW_DEG = 0.03, 0.4


def homogeneous(rows: np.ndarray) -> np.ndarray:
    return np.vstack([rows.reshape(3, 4), [0.0, 0.0, 0.0, 1.0]])


def drifted(poses: np.ndarray) -> np.ndarray:
    """The poses (K, 4, 4) re-integrated with every relative motion's translation GAIN longer
    and YAW_DEG more turn about its z axis."""
    c, s = np.cos(np.radians(YAW_DEG)), np.sin(np.radians(YAW_DEG))
    turn = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    out = [poses[0]]
    for a, b in zip(poses[:-1], poses[1:], strict=True):
        step = np.linalg.inv(a) @ b
        step[:3, 3] *= 1.0 + GAIN
        out.append(out[-1] @ step @ turn)
    return np.array(out)


def rpe_rmse(estimate: np.ndarray, reference: np.ndarray) -> float:
    """RMSE of the translation of (ref_i^-1 ref_i+1)^-1 (est_i^-1 est_i+1), metres."""
    inv = np.linalg.inv
    errors = [inv(inv(r0) @ r1) @ (inv(e0) @ e1)
              for e0, e1, r0, r1 in zip(estimate[:-1], estimate[1:], reference[:-1],
                                        reference[1:], strict=True)]
    return float(np.sqrt(np.mean([np.sum(e[:3, 3] ** 2) for e in errors])))


@pytest.fixture(scope="module")
def kitti(tmp_path_factory) -> dict[str, Path | np.ndarray]:
    """The first SCANS KITTI scans; KITTI's camera poses as the reference; the estimate in the
    LiDAR frame (as KISS-ICP's), drifted; the reference map built on the LiDAR poses."""
    folder = shared("kitti00")
    tmp = tmp_path_factory.mktemp("kitti_calib")
    scans = tmp / "velodyne"
    scans.mkdir()
    for scan in sorted((folder / "velodyne").glob("*.bin"))[:SCANS]:
        (scans / scan.name).symlink_to(scan)
    camera = read_poses(folder / "poses.txt")[:SCANS]
    tr = homogeneous(TR)
    lidar = np.linalg.inv(tr) @ camera @ tr
    estimate = drifted(lidar)
    write_kitti_poses(tmp / "reference.txt", camera)
    write_kitti_poses(tmp / "estimate.txt", estimate)
    np.savetxt(tmp / "Tr.txt", TR.reshape(3, 4))
    write_cloud(tmp / "ref.ply", build_map_from_poses(open_scans(scans), lidar, voxel=0.2).points)
    return {"folder": tmp, "camera": camera, "lidar": lidar, "estimate": estimate}


def track(kitti, *extra: str, every: int = EVERY) -> tuple[list[dict], str]:
    tmp = kitti["folder"]
    out = tmp / ("out" + "".join(extra).replace("-", "").replace("/", ""))
    got = CliRunner().invoke(app, [
        "track", str(tmp / "velodyne"), str(tmp / "ref.ply"), "--poses", str(tmp / "estimate.txt"),
        "--reference-poses", str(tmp / "reference.txt"), "--every", str(every), "--no-align",
        "--out", str(out), "--quiet", *extra])
    assert got.exit_code == 0, got.stderr
    return json.loads((out / "track.json").read_text())["steps"], got.stderr


def test_track_with_calib_reports_pose_errors_in_the_lidar_frame(kitti) -> None:
    """With --calib, every step's RPE equals the LiDAR-frame figure of its scans so far, to
    1e-6 m, and no warning is given; without it, the camera-frame poses are taken as the
    scanner's (one warning naming the file) and the RPE is the frames' mismatch, far larger."""
    tmp = kitti["folder"]
    steps, stderr = track(kitti, "--calib", str(tmp / "Tr.txt"))
    assert "warning" not in stderr.lower(), stderr
    assert len(steps) == SCANS // EVERY
    for step in steps:
        n = step["scans"]
        want = rpe_rmse(kitti["estimate"][:n], kitti["lidar"][:n])
        assert abs(step["rpe_rmse_m"] - want) < 1e-6, (n, step["rpe_rmse_m"], want)
        assert want > 0.01  # the drift shows
    steps, stderr = track(kitti, every=SCANS)  # one step: all the scans
    assert str(tmp / "reference.txt") in stderr and "--calib" in stderr, stderr
    assert [step["scans"] for step in steps] == [SCANS]
    for step in steps:
        n = step["scans"]
        assert abs(step["rpe_rmse_m"] - rpe_rmse(kitti["estimate"][:n], kitti["camera"][:n])) < 1e-6
        assert step["rpe_rmse_m"] > 5 * rpe_rmse(kitti["estimate"][:n], kitti["lidar"][:n])


def test_every_step_of_a_3d_run_is_registered_in_3d(kitti) -> None:
    """Aligned (no --no-align), each step after the first starts its ICP from the step
    before's 3D registration, as the first is registered: every step has the 3D figures (AWD,
    the 3D consistency map's largest offset), not the first step alone."""
    tmp = kitti["folder"]
    out = tmp / "aligned_3d"
    got = CliRunner().invoke(app, [
        "track", str(tmp / "velodyne"), str(tmp / "ref.ply"), "--poses", str(tmp / "estimate.txt"),
        "--every", str(EVERY), "--out", str(out), "--quiet"])
    assert got.exit_code == 0, got.stderr
    steps = json.loads((out / "track.json").read_text())["steps"]
    assert [step["scans"] for step in steps] == list(range(EVERY, SCANS + 1, EVERY))
    for step in steps:
        assert step["awd_m"] is not None and step["largest_offset_3d_m"] is not None, step
        assert step["awd_m"] < 0.5


def test_a_log_scored_against_itself_ends_at_one(tmp_path) -> None:
    """The FHW run of docs/commands/track.md against itself (docs/metrics.md, 'A run scored
    against itself'): at the last step the map is the truth, every quality and precision 1;
    its coverage under the 'seen' footprint stays below 1 by the far walls drawn as dots
    (0.953), and is 1 with --footprint all."""
    log = shared("carmen", "fhw-corrected.log.gz")
    for footprint, coverage in (("auto", (0.9, 0.99)), ("all", (1.0, 1.0))):
        out = tmp_path / footprint
        got = CliRunner().invoke(app, ["track", str(log), str(log), "--every", "1000",
                                       "--footprint", footprint, "--out", str(out), "--quiet"])
        assert got.exit_code == 0, got.stderr
        last = json.loads((out / "track.json").read_text())["steps"][-1]
        for name in ("harris", "hough", "sift"):
            assert last[f"{name}_quality"] == last[f"{name}_precision"] == 1.0, (name, last)
        assert coverage[0] <= last["coverage"] <= coverage[1], last["coverage"]


def test_the_first_steps_of_a_small_map_are_placed_at_their_pose() -> None:
    """ACES's first 20 and 40 scans (5 and 25 m of corridor) against the map of the whole
    corrected log, in one frame: the global search weighs a pose by the map's free space only
    where enough of it is clear of the map's walls at the search's coarse cell, so such a small
    map is placed where it is (within 1 cm and 0.1 degree), not half a building away."""
    from pcmapq.settings import Settings
    from pcmapq.track import open_run, track_run

    log = shared("carmen", "aces-corrected.log.gz")
    run = open_run(log)
    steps = track_run(run, log, Settings(), np.array([20, 40])).steps
    for step in steps:
        figures = step.figures
        assert step.scored and figures["verdict"] == "same place", (step.step, step.note)
        assert abs(figures["x_m"]) < 0.01 and abs(figures["y_m"]) < 0.01, figures
        assert abs(figures["yaw_deg"]) < 0.1, figures
