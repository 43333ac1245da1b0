"""Trajectory errors as evo computes them, on trajectories with known errors: a known rigid
move (APE 0 after alignment, its offset without), a known scale (Sim(3)), a yaw drift injected
at a known pose (RPE 0 before it), pairs by poses and by metres on a path of known lengths."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pcmapq.errors import InputError
from pcmapq.trajectory import (
    ape,
    pairs_by_index,
    pairs_by_path,
    rpe,
    statistics,
    umeyama,
)


def pose(x: float, y: float, z: float, yaw_deg: float, pitch_deg: float = 0.0) -> np.ndarray:
    p = np.eye(4)
    p[:3, :3] = Rotation.from_euler("zy", [yaw_deg, pitch_deg], degrees=True).as_matrix()
    p[:3, 3] = (x, y, z)
    return p


def wiggly(n: int = 40) -> np.ndarray:
    """A 3D path of n poses turning and climbing, world <- body."""
    t = np.arange(n, dtype=np.float64)
    return np.stack([pose(np.cos(0.2 * k) * 5, np.sin(0.3 * k) * 4, 0.1 * k, 7.0 * k, 3.0 * k)
                     for k in t])


def test_a_rigidly_moved_estimate():
    ref = wiggly()
    move = pose(3.0, -2.0, 1.0, 30.0, 10.0)
    est = move @ ref
    assert ape(est, ref, align=True).max() < 1e-9
    assert ape(est, ref, "rotation", align=True).max() < 1e-5
    assert ape(est, ref, align_origin=True).max() < 1e-9  # the first poses fix the move
    raw = ape(est, ref)  # unaligned: each position's offset
    want = np.linalg.norm((move @ ref)[:, :3, 3] - ref[:, :3, 3], axis=1)
    np.testing.assert_allclose(raw, want, atol=1e-12)
    np.testing.assert_allclose(ape(est, ref, "rotation"), np.degrees(
        Rotation.from_matrix(move[:3, :3]).magnitude()), atol=1e-6)


def test_a_known_scale_is_corrected():
    ref = wiggly()
    est = ref.copy()
    est[:, :3, 3] /= 1.5
    r, t, s = umeyama(est[:, :3, 3], ref[:, :3, 3], with_scale=True)
    assert s == pytest.approx(1.5, rel=1e-12) and np.allclose(r, np.eye(3))
    assert np.allclose(t, 0.0, atol=1e-12)
    assert ape(est, ref, align=True, correct_scale=True).max() < 1e-9
    assert ape(est, ref, align=True).max() > 0.5  # SE(3) alone cannot undo a scale


def test_yaw_drift_from_a_known_pose():
    """The estimate turns 2 degrees more than the reference at each step from pose 20 on: the
    RPE of consecutive pairs is 0 before 20 and 2 degrees from there."""
    n, k = 40, 20
    steps = [pose(1.0, 0.0, 0.0, 5.0)] * (n - 1)
    ref, est = [np.eye(4)], [np.eye(4)]
    for i, step in enumerate(steps):
        ref.append(ref[-1] @ step)
        extra = pose(0.0, 0.0, 0.0, 2.0) if i + 1 >= k else np.eye(4)
        est.append(est[-1] @ step @ extra)
    ref, est = np.stack(ref), np.stack(est)
    angles = rpe(est, ref, pairs_by_index(n, 1), "rotation")
    assert angles[:k - 1].max() < 1e-6
    np.testing.assert_allclose(angles[k - 1:], 2.0, atol=1e-6)
    assert rpe(est, ref, pairs_by_index(n, 1))[:k - 1].max() < 1e-9


def test_pairs_by_index_as_evo():
    np.testing.assert_array_equal(pairs_by_index(7, 3), [[0, 3], [3, 6]])
    np.testing.assert_array_equal(pairs_by_index(5, 3, all_pairs=True), [[0, 3], [1, 4]])


def test_pairs_by_path_on_known_lengths():
    """Steps of 1, 1, 2, 1, 1, 3 m: consecutive pairs 2 m apart along the path start where the
    path first reaches 2 m (pose 2), then restart the count; all pairs: each pose with the later
    one nearest 2 m ahead, kept only at exactly 2 m (tol 0: from pose 1 the nearest are 1 and
    3 m ahead, from pose 4 1 m)."""
    steps = [1.0, 1.0, 2.0, 1.0, 1.0, 3.0]
    x = np.r_[0.0, np.cumsum(steps)]
    positions = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    np.testing.assert_array_equal(pairs_by_path(positions, 2.0), [[2, 3], [3, 5], [5, 6]])
    np.testing.assert_array_equal(pairs_by_path(positions, 2.0, tol=0.0, all_pairs=True),
                                  [[0, 2], [2, 3], [3, 5]])
    np.testing.assert_array_equal(pairs_by_path(positions, 2.0, tol=1.0, all_pairs=True),
                                  [[0, 2], [1, 2], [2, 3], [3, 5], [4, 5], [5, 6]])


def test_statistics_as_evo():
    s = statistics(np.array([3.0, 4.0]))
    assert (s.rmse, s.mean, s.median, s.std, s.min, s.max, s.sse, s.count) == (
        pytest.approx(np.sqrt(12.5)), 3.5, 3.5, 0.5, 3.0, 4.0, 25.0, 2)
    with pytest.raises(InputError):
        statistics(np.array([]))


def test_unpaired_trajectories_are_refused():
    with pytest.raises(InputError, match="paired by index"):
        ape(wiggly(5), wiggly(6))
