"""The pose drifts of testkit.kitti that the 3D ladders use, on a straight run with known
answers: a heading drift bends the run into an arc, a pitch drift bends it down, a scale
drift stretches it, the first pose kept."""

from __future__ import annotations

import numpy as np
import pytest

from testkit.kitti import curved, pitched, stretched, turn
from testkit.realdata.ladders3d import drifted

pytestmark = pytest.mark.unit


def straight(k: int = 11, step: float = 1.0) -> np.ndarray:
    """K poses 1 m apart along +x from (2, 3, 1), not turned."""
    poses = np.tile(np.eye(4), (k, 1, 1))
    poses[:, :3, 3] = [2.0, 3.0, 1.0]
    poses[:, 0, 3] += step * np.arange(k)
    return poses


def yaw(pose: np.ndarray) -> float:
    return float(np.degrees(np.arctan2(pose[1, 0], pose[0, 0])))


def test_heading_drift_turns_each_scan_more_and_curves_the_run_left():
    poses = curved(straight(), "z", 2.0)
    assert np.allclose(poses[0], straight()[0])
    assert [round(yaw(p), 9) for p in poses] == [2.0 * k for k in range(11)]
    # step k leaves scan k-1 along its own heading, turned 2 degrees more: an arc to the left
    headings = np.radians(2.0 * np.arange(1, 11))
    expected = np.cumsum(np.column_stack([np.cos(headings), np.sin(headings)]), axis=0)
    assert np.allclose(poses[1:, :2, 3] - [2.0, 3.0], expected)
    assert np.allclose(poses[:, 2, 3], 1.0)
    assert np.allclose(np.linalg.norm(np.diff(poses[:, :3, 3], axis=0), axis=1), 1.0)


def test_pitch_drift_bends_the_run_down_as_pitched_turns_its_scans():
    poses = curved(straight(), "y", 1.0)
    assert np.allclose(poses[:, :3, :3], pitched(straight(), 1.0)[:, :3, :3])
    angles = np.radians(np.arange(1, 11))
    assert np.allclose(poses[1:, 2, 3], 1.0 - np.cumsum(np.sin(angles)))
    assert np.allclose(drifted(straight(), "vertical", 1.0), poses)


def test_scale_drift_stretches_every_step():
    poses = stretched(straight(), 0.1)
    assert np.allclose(poses[:, 0, 3], 2.0 + 1.1 * np.arange(11))
    assert np.allclose(poses[:, :3, :3], np.eye(3))
    assert np.allclose(drifted(straight(), "scale", 0.1), poses)


def test_turn_is_right_handed():
    assert np.allclose(turn("z", 90.0)[:3, :3] @ [1, 0, 0], [0, 1, 0])
    assert np.allclose(turn("y", 90.0)[:3, :3] @ [1, 0, 0], [0, 0, -1])
    assert np.allclose(turn("x", 90.0)[:3, :3] @ [0, 1, 0], [0, 0, 1])
