"""Trajectory errors (pcmapq.metrics.trajectory): APE and RPE as evo defines them, known
answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pcmapq.core.errors import EvaluationError
from pcmapq.metrics.trajectory import (
    align_umeyama,
    ape,
    pairs_by_frames,
    pairs_by_path,
    path_lengths,
    rpe,
)


def se3(rotvec_deg, t) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    m[:3, 3] = t
    return m


def wander(n: int = 60, seed: int = 0, tilt: float = 3.0) -> np.ndarray:
    """A smooth 3D path (N, 4, 4): 1 m steps, turning and climbing a little (roll and pitch
    steps of ``tilt`` degrees; 0: a plane)."""
    rng = np.random.default_rng(seed)
    poses = [np.eye(4)]
    for _ in range(n - 1):
        step = se3(rng.normal(0, [tilt, tilt, 15]), [1.0, 0.0, 0.0])
        poses.append(poses[-1] @ step)
    return np.array(poses)


def moved(poses: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.einsum("ij,njk->nik", t, poses)


T = se3([0, 0, 30], [2.0, -1.0, 0.5])


# --- APE ---------------------------------------------------------------------------------


def test_a_rigidly_moved_estimate_has_no_ape_once_aligned():
    ref = wander()
    est = moved(ref, T)
    for relation in ("translation_part", "rotation_angle_deg", "full"):
        r = ape(est, ref, relation, align=True)
        assert r.stats.max < 1e-9, relation
        assert r.stats.count == len(ref)
    a = ape(est, ref, align=True).alignment
    np.testing.assert_allclose(a.matrix(), np.linalg.inv(T), atol=1e-12)
    assert ape(est, ref, align_origin=True).stats.max < 1e-9


def test_without_alignment_the_ape_is_the_transforms_offset():
    ref = wander()
    est = moved(ref, T)
    got = ape(est, ref).errors
    expected = np.linalg.norm(ref[:, :3, 3] @ T[:3, :3].T + T[:3, 3] - ref[:, :3, 3], axis=1)
    np.testing.assert_allclose(got, expected, atol=1e-12)
    # E_i = (T ref_i)^-1 ref_i: a conjugate of T's rotation, 30 degrees for every pose.
    np.testing.assert_allclose(ape(est, ref, "rotation_angle_deg").errors, 30.0, atol=1e-9)
    shifted = moved(ref, se3([0, 0, 0], [3.0, 4.0, 0.0]))
    np.testing.assert_allclose(ape(shifted, ref).errors, 5.0, atol=1e-12)


def test_sim3_alignment_recovers_a_known_scale():
    ref = wander()
    small = ref.copy()
    small[:, :3, 3] /= 1.5
    est = moved(small, T)
    r = ape(est, ref, align=True, correct_scale=True)
    assert r.alignment.scale == pytest.approx(1.5, rel=1e-12)
    assert r.stats.max < 1e-9
    assert ape(est, ref, align=True).stats.max > 1.0  # SE(3) cannot undo a scale
    only = ape(small, ref, correct_scale=True)  # evo's correct_scale without align
    assert only.alignment.scale == pytest.approx(1.5, rel=1e-12)
    np.testing.assert_allclose(only.alignment.rotation, np.eye(3))
    assert only.stats.max < 1e-9


def test_umeyama_is_the_least_squares_fit():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(40, 3))
    rot = Rotation.from_rotvec([0.2, -0.4, 1.0]).as_matrix()
    y = 0.7 * x @ rot.T + [1.0, 2.0, 3.0]
    r, t, s = align_umeyama(x, y, with_scale=True)
    np.testing.assert_allclose(r, rot, atol=1e-12)
    np.testing.assert_allclose(t, [1.0, 2.0, 3.0], atol=1e-12)
    assert s == pytest.approx(0.7, rel=1e-12)
    _, _, s1 = align_umeyama(x, y, with_scale=False)
    assert s1 == 1.0
    line = np.outer(np.arange(5.0), [1.0, 0.0, 0.0])
    with pytest.raises(EvaluationError, match="Umeyama"):
        align_umeyama(line, line, with_scale=False)


def test_statistics_are_evos():
    ref = wander(4)
    est = ref.copy()
    est[:, :3, 3] += [[1, 0, 0], [0, 2, 0], [0, 0, 2], [3, 4, 0]]  # errors 1, 2, 2, 5 m
    r = ape(est, ref)
    np.testing.assert_allclose(r.errors, [1, 2, 2, 5], atol=1e-12)
    assert r.unit == "m"
    st = r.statistics()
    expected = {"rmse": np.sqrt(34 / 4), "mean": 2.5, "median": 2.0,
                "std": 1.5,  # population: sqrt((2.25 + 0.25 + 0.25 + 6.25) / 4)
                "min": 1.0, "max": 5.0, "sse": 34.0}
    assert st.keys() == expected.keys()
    for k, v in expected.items():
        assert st[k] == pytest.approx(v, abs=1e-12), k


# --- RPE ---------------------------------------------------------------------------------


def drifted(ref: np.ndarray, k: int, yaw_deg: float) -> np.ndarray:
    """``ref`` with each step after pose k turned by an extra yaw before it is taken."""
    est = [ref[0]]
    for i in range(len(ref) - 1):
        step = np.linalg.inv(ref[i]) @ ref[i + 1]
        if i >= k:
            step = se3([0, 0, yaw_deg], [0, 0, 0]) @ step
        est.append(est[-1] @ step)
    return np.array(est)


def test_yaw_drift_after_pose_k_shows_in_the_rpe_after_k_only():
    ref, k, yaw = wander(50, tilt=0.0), 20, 2.0
    est = drifted(ref, k, yaw)
    rot = rpe(est, ref, relation="rotation_angle_deg")
    tra = rpe(est, ref)
    np.testing.assert_array_equal(rot.pairs[:, 1] - rot.pairs[:, 0], 1)
    before = rot.pairs[:, 0] < k
    assert rot.errors[before].max() < 1e-9 and tra.errors[before].max() < 1e-9
    # E = step^-1 Rz step: the yaw's angle, and a 1 m step turned by it moves 2 sin(yaw/2).
    np.testing.assert_allclose(rot.errors[~before], yaw, atol=1e-9)
    np.testing.assert_allclose(tra.errors[~before], 2 * np.sin(np.radians(yaw / 2)),
                               atol=1e-12)
    assert rot.unit == "deg" and tra.unit == "m"
    # A rigid alignment does not change the RPE; in a plane, 5 frames turn by 5 yaws.
    np.testing.assert_allclose(rpe(est, ref, align=True).errors, tra.errors, atol=1e-9)
    five = rpe(est, ref, delta=5, relation="rotation_angle_deg")
    np.testing.assert_array_equal(five.pairs[:3], [[0, 5], [5, 10], [10, 15]])
    np.testing.assert_allclose(five.errors[five.pairs[:, 0] >= k], 5 * yaw, atol=1e-9)


def test_pairs_by_frames():
    np.testing.assert_array_equal(pairs_by_frames(7, 3), [[0, 3], [3, 6]])
    np.testing.assert_array_equal(pairs_by_frames(5, 3, all_pairs=True), [[0, 3], [1, 4]])
    assert pairs_by_frames(2, 3).shape == (0, 2)


def path(steps) -> np.ndarray:
    """Positions (N, 3) after axis-aligned steps of the given lengths, cycling x, y, z."""
    moves = np.zeros((len(steps), 3))
    moves[np.arange(len(steps)), np.arange(len(steps)) % 3] = steps
    return np.vstack([np.zeros(3), np.cumsum(moves, axis=0)])


def test_pairs_by_path_in_metres_are_evos():
    xyz = path([0.5, 0.5, 1.0, 0.25, 0.25, 0.25, 0.25, 2.0, 0.5])
    np.testing.assert_array_equal(path_lengths(xyz), [0, .5, 1, 2, 2.25, 2.5, 2.75, 3, 5, 5.5])
    # Consecutive: from 0 the first pose 1 m of path on, then on from there.
    np.testing.assert_array_equal(pairs_by_path(xyz, 1.0), [[0, 2], [2, 3], [3, 7], [7, 8]])
    # All pairs: for each i the j nearest 1 m on (the first on ties: i = 1 takes 2 over 3),
    # kept within 0.1 m; within 0.3 m, i = 4 (0.75 m to pose 7) joins.
    np.testing.assert_array_equal(pairs_by_path(xyz, 1.0, 0.1, all_pairs=True),
                                  [[0, 2], [2, 3], [3, 7]])
    np.testing.assert_array_equal(pairs_by_path(xyz, 1.0, 0.3, all_pairs=True),
                                  [[0, 2], [2, 3], [3, 7], [4, 7]])
    # A halt (equal positions) counts from its first pose.
    halt = path([1.0, 0.0, 0.0, 1.0])
    np.testing.assert_array_equal(pairs_by_path(halt, 1.0), [[0, 1], [1, 4]])
    np.testing.assert_array_equal(pairs_by_path(halt, 1.0, 0.0, all_pairs=True),
                                  [[0, 1], [1, 4], [2, 4], [3, 4]])


def test_rpe_in_metres_pairs_along_the_estimate_unless_told():
    ref = np.tile(np.eye(4), (10, 1, 1))
    ref[:, :3, 3] = path([0.5, 0.5, 1.0, 0.25, 0.25, 0.25, 0.25, 2.0, 0.5])
    est = ref.copy()
    est[:, :3, 3] *= 2.0  # twice the path: 1 m of it is every step of 0.5 m
    on_est = rpe(est, ref, delta=1.0, delta_unit="metres")
    np.testing.assert_array_equal(on_est.pairs[:3], [[0, 1], [1, 2], [2, 3]])
    on_ref = rpe(est, ref, delta=1.0, delta_unit="metres", pairs_from_reference=True)
    np.testing.assert_array_equal(on_ref.pairs, [[0, 2], [2, 3], [3, 7], [7, 8]])
    # Scale-corrected first (s = 0.5 to 1e-16, so these exact 1 m ties may fall either way),
    # the estimate's relative poses are the reference's.
    fixed = rpe(est, ref, delta=1.0, delta_unit="metres", correct_scale=True)
    assert fixed.alignment.scale == pytest.approx(0.5) and fixed.stats.max < 1e-9
    assert rpe(est, ref, delta=1.0, delta_unit="metres").stats.max > 0.4
    none = rpe(est[:2], ref[:2], delta=5.0, delta_unit="metres")
    assert none.stats.count == 0 and none.stats.rmse is None and none.sse is None


def test_bad_arguments_are_refused():
    ref = wander(5)
    with pytest.raises(ValueError, match="as many"):
        ape(ref[:4], ref)
    with pytest.raises(ValueError, match="together"):
        ape(ref, ref, align=True, align_origin=True)
    with pytest.raises(ValueError, match="relation"):
        ape(ref, ref, "rotation_part")
    with pytest.raises(ValueError, match="integer"):
        rpe(ref, ref, delta=1.5)
    with pytest.raises(ValueError, match="positive"):
        rpe(ref, ref, delta=0.0, delta_unit="metres")


# --- The same numbers as evo itself, where it is installed --------------------------------


def test_the_errors_equal_evos():
    metrics = pytest.importorskip("evo.core.metrics",
                                  reason="evo is not installed (pip install evo to compare)")
    from evo.core.trajectory import PosePath3D
    from evo.main_ape import ape as evo_ape

    rng = np.random.default_rng(3)
    ref = wander(150, seed=2)
    noise = np.array([se3(rng.normal(0, 1.0, 3), rng.normal(0, 0.05, 3)) for _ in ref])
    est = moved(drifted(ref, 60, 0.5) @ noise, T)
    est[:, :3, 3] *= 0.8
    rel = {"translation_part": metrics.PoseRelation.translation_part,
           "rotation_angle_deg": metrics.PoseRelation.rotation_angle_deg,
           "full": metrics.PoseRelation.full_transformation}
    units = {"frames": metrics.Unit.frames, "metres": metrics.Unit.meters}

    def paths():
        return PosePath3D(poses_se3=list(ref.copy())), PosePath3D(poses_se3=list(est.copy()))

    aligns = [{}, {"align": True}, {"align": True, "correct_scale": True},
              {"correct_scale": True}, {"align_origin": True}]
    for relation, evo_rel in rel.items():
        for kw in aligns:
            mine = ape(est, ref, relation, **kw)
            theirs = evo_ape(*paths(), evo_rel, **kw)
            np.testing.assert_allclose(mine.errors, theirs.np_arrays["error_array"],
                                       rtol=1e-9, atol=1e-9, err_msg=f"{relation} {kw}")
            for k, v in theirs.stats.items():
                assert mine.statistics()[k] == pytest.approx(v, rel=1e-9, abs=1e-9), k
    for unit, delta, all_pairs, from_ref, kw in [
            ("frames", 1, False, False, {}), ("frames", 7, True, False, {}),
            ("metres", 4.0, False, False, {}), ("metres", 4.0, False, True, {}),
            ("metres", 3.0, True, False, {"align": True, "correct_scale": True}),
            ("metres", 10.0, True, True, {})]:
        for relation, evo_rel in rel.items():
            mine = rpe(est, ref, delta, unit, relation, all_pairs,
                       pairs_from_reference=from_ref, **kw)
            evo_ref, evo_est = paths()
            if kw:
                evo_est.align(evo_ref, correct_scale=True)
            theirs = metrics.RPE(evo_rel, delta, units[unit], all_pairs=all_pairs,
                                 pairs_from_reference=from_ref)
            theirs.process_data((evo_ref, evo_est))
            what = f"{relation} {unit} {delta} all={all_pairs} ref={from_ref} {kw}"
            assert len(mine.errors) > 10, what
            np.testing.assert_array_equal(mine.pairs[:, 1], theirs.delta_ids, err_msg=what)
            np.testing.assert_allclose(mine.errors, theirs.error,
                                       rtol=1e-9, atol=1e-9, err_msg=what)
