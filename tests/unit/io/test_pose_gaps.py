"""Scans far in time from the poses that place them (a recording's odometry or moving
transforms): placed silently within GAP_WARN_S of the nearest pose, with a warning giving the
gap beyond it, refused beyond GAP_MAX_S."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io.bag_scans import GAP_MAX_S, GAP_WARN_S, pose_gaps
from pcmapq.mapping import recorded_poses
from testkit.recordings import Cloud, write_recording

#: Scans one a second from 10 s of the bag's clock (the recording's start: 0 s).
SCAN_TIMES = [10.0 + k for k in range(6)]


def moving(times: list[float]) -> list[tuple[float, np.ndarray]]:
    """A pose at each of ``times``: moving east 0.5 m a second."""
    poses = []
    for t in times:
        pose = np.eye(4)
        pose[0, 3] = 0.5 * t
        poses.append((t, pose))
    return poses


def recording(tmp_path: Path, pose_times: list[float], tf: bool) -> Path:
    """Scans at SCAN_TIMES, poses at ``pose_times`` as odometry (/odom) or /tf (odom ->
    laser)."""
    points = np.random.default_rng(1).uniform(-3, 3, (40, 3))
    poses = moving(pose_times)
    return write_recording(tmp_path / "run.mcap", [], "mcap",
                           scans=[Cloud(t, points) for t in SCAN_TIMES], scan_topic="/points",
                           poses=[] if tf else poses,
                           transforms=[(t, "odom", "laser", p) for t, p in poses] if tf else ())


def test_the_gap_is_the_time_to_the_nearest_pose() -> None:
    got = pose_gaps(np.array([0.0, 1.2, 2.5, 9.0]), np.array([3.0, 1.0, 2.0]))
    assert np.allclose(got, [1.0, 0.2, 0.5, 6.0])


@pytest.mark.parametrize("tf", [False, True], ids=["odometry", "tf"])
def test_scans_near_their_poses_are_placed_silently(tmp_path: Path, tf: bool) -> None:
    path = recording(tmp_path, [t + 0.3 for t in SCAN_TIMES], tf)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        poses = recorded_poses(path, None, "/tf" if tf else "/odom")
    assert len(poses) == len(SCAN_TIMES)


@pytest.mark.parametrize("tf", [False, True], ids=["odometry", "tf"])
def test_scans_before_the_first_pose_get_a_warning_with_the_gap(tmp_path: Path,
                                                                tf: bool) -> None:
    """The poses start 2 s after the first scan: two scans are 2 s and 1 s from them."""
    path = recording(tmp_path, [12.0, 13.0, 14.0, 15.0], tf)
    source = "/tf (odom -> laser)" if tf else "/odom"
    with pytest.warns(UserWarning) as caught:
        poses = recorded_poses(path, None, "/tf" if tf else "/odom")
    assert [str(w.message) for w in caught] == [
        f"{path}: 2 of 6 scans (recorded 0.0 to 1.0 s from its start) lie up to 2.0 s from the "
        f"nearest pose of {source}, more than {GAP_WARN_S:g} s: they are placed at poses held "
        "or interpolated across that gap"]
    assert np.allclose(poses[:3, 0, 3], 6.0)  # held at the first pose


@pytest.mark.parametrize("tf", [False, True], ids=["odometry", "tf"])
def test_scans_far_from_every_pose_are_refused(tmp_path: Path, tf: bool) -> None:
    """The poses start 7 s after the first scan."""
    path = recording(tmp_path, [17.0, 18.0, 19.0], tf)
    source = "/tf (odom -> laser)" if tf else "/odom"
    with pytest.raises(InputError) as err:
        recorded_poses(path, None, "/tf" if tf else "/odom")
    assert str(err.value) == (
        f"{path}: 6 of 6 scans (recorded 0.0 to 5.0 s from its start) lie up to 7.0 s from "
        f"the nearest pose of {source}, more than {GAP_MAX_S:g} s: their poses would be "
        "guesses; give poses that cover the scans' time, or cut the recording to the poses' "
        "time")
