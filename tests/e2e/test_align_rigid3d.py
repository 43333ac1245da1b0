"""3D rigid registration (FPFH + RANSAC + point-to-plane ICP) with no initial guess."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align import refine3d
from pcmapq.align.features3d import feature_matches, keypoints
from pcmapq.align.rigid3d import align_3d
from pcmapq.core.errors import EvaluationError, InputError
from testkit.poses import apply, errors, rigid


def room(seed: int = 0) -> np.ndarray:
    """An asymmetric room 12 x 8 x 3 m (floor, walls) with boxes inside, 2 cm point noise."""
    rng = np.random.default_rng(seed)
    n = 6000
    u, v = rng.uniform(size=(2, n))
    faces = [
        np.column_stack([12 * u, 8 * v, 0 * u]),            # floor
        np.column_stack([12 * u, 0 * u, 3 * v]),            # walls
        np.column_stack([12 * u, 8 + 0 * u, 3 * v]),
        np.column_stack([0 * u, 8 * u, 3 * v]),
        np.column_stack([12 + 0 * u, 8 * u, 3 * v]),
    ]
    for (x, y, w, d, h) in [(2, 2, 1.0, 0.6, 0.8), (7, 5, 2.0, 1.0, 1.2), (9.5, 1.0, 0.5, 0.5, 2)]:
        top = np.column_stack([x + w * u[:1500], y + d * v[:1500], h + 0 * u[:1500]])
        side = np.column_stack([x + 0 * u[:1500], y + d * u[:1500], h * v[:1500]])
        front = np.column_stack([x + w * u[:1500], y + 0 * u[:1500], h * v[:1500]])
        faces += [top, side, front]
    points = np.vstack(faces)
    return points + rng.normal(scale=0.02, size=points.shape)


def test_synthetic_room_any_pose() -> None:
    target = room(0)
    truth = rigid((20.0, -10.0, 130.0), (3.0, -7.0, 0.5))
    source = apply(np.linalg.inv(truth), room(1))  # other samples of the same room
    transform, fitness, rmse = align_3d(source, target, voxel=0.2)
    shift, angle = errors(transform, truth)
    assert shift < 0.02 and angle < 0.2
    assert fitness > 0.95 and rmse < 0.1


def test_initial_guess_skips_the_global_search() -> None:
    target = room(0)
    truth = rigid((0.0, 0.0, 3.0), (0.2, -0.1, 0.0))
    source = apply(np.linalg.inv(truth), room(1))
    result = align_3d(source, target, voxel=0.2, init=np.eye(4))
    shift, angle = errors(result.transform, truth)
    assert shift < 0.02 and angle < 0.2


def test_a_second_guess_is_asked_for_only_where_the_global_search_fits_poorly() -> None:
    target = room(0)
    truth = rigid((0.0, 0.0, 40.0), (1.0, -2.0, 0.3))
    source = apply(np.linalg.inv(truth), room(1))

    def second() -> np.ndarray:
        raise AssertionError("a second guess was asked for where the first fits")

    shift, angle = errors(align_3d(source, target, voxel=0.2, second=second).transform, truth)
    assert shift < 0.02 and angle < 0.2


def test_a_second_guess_that_fits_more_is_refined(monkeypatch) -> None:
    """The global search's guess turned upside down (as alike features can give it) fits
    little of the room: the second guess, which fits it, is the one refined."""
    from pcmapq.align import features3d

    target = room(0)
    truth = rigid((0.0, 0.0, 40.0), (1.0, -2.0, 0.3))
    source = apply(np.linalg.inv(truth), room(1))
    flipped = rigid((180.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    monkeypatch.setattr(features3d, "global_registration", lambda *_: flipped)
    shift, angle = errors(align_3d(source, target, voxel=0.2).transform, truth)
    assert angle > 90.0  # the flipped guess alone stays wrong
    near = truth @ rigid((0.0, 0.0, 3.0), (0.3, -0.2, 0.0))
    shift, angle = errors(align_3d(source, target, voxel=0.2, second=lambda: near).transform,
                          truth)
    assert shift < 0.02 and angle < 0.2


def test_the_target_prepared_on_every_core_gives_the_same_registration(monkeypatch) -> None:
    """The target's KD-tree and normals built on 4 threads give the transform of one thread,
    bit for bit."""
    target = room(0)
    source = apply(np.linalg.inv(rigid((0.0, 0.0, 3.0), (0.2, -0.1, 0.0))), room(1))
    got = []
    for threads in (1, 4):
        monkeypatch.setattr(refine3d, "PREPARE_THREADS", threads)
        got.append(align_3d(source, target, voxel=0.2, init=np.eye(4)).transform)
    assert np.array_equal(got[0], got[1])


def test_keypoints_and_matches_are_small_and_mutual() -> None:
    points = room(0)
    keys = keypoints(points, 0.5)
    assert np.all(np.diff(keys) > 0) and len(keys) < len(points)
    features = np.random.default_rng(0).uniform(size=(50, 33))
    pairs = feature_matches(features, features[::-1])
    assert np.array_equal(pairs[:, 1], 49 - pairs[:, 0]) and len(pairs) == 50


def test_rejects_bad_input() -> None:
    with pytest.raises(InputError, match="N x 3"):
        align_3d(np.zeros((5, 2)), room(0))
    with pytest.raises(InputError, match="no usable points"):
        align_3d(np.zeros((5, 3)), room(0))
    with pytest.raises(EvaluationError, match="too few points"):
        align_3d(np.array([[1.0, 1.0, 1.0]]), room(0))


def test_far_from_the_origin() -> None:
    """UTM-like target coordinates (thousands of km) work: the clouds are centred first."""
    truth = rigid((0.0, 0.0, 70.0), (4.5e5, 5.4e6, 120.0))
    target = apply(truth, room(0))
    result = align_3d(room(1), target, voxel=0.2)
    shift, angle = errors(result.transform, truth)
    assert shift < 0.02 and angle < 0.2


def test_the_clouds_are_copied_once_each():
    """Two float32 clouds (files mapped into memory): the registration holds one float64 copy
    of each (shifted in place, no copy when every point is usable), not four."""
    import tracemalloc

    from testkit.street import street

    truth = street(0.0, 40.0, spacing=0.03, seed=0).astype(np.float32)
    moved = (street(0.0, 40.0, spacing=0.03, seed=0) + [0.2, 0.1, 0.0]).astype(np.float32)
    align_3d(moved, truth, voxel=0.3)  # compiled code loaded before the measure
    tracemalloc.start()
    try:
        reg = align_3d(moved, truth, voxel=0.3)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    np.testing.assert_allclose(reg.transform[:3, 3], [-0.2, -0.1, 0.0], atol=0.02)
    assert peak < 2 * 2 * truth.nbytes * 2  # two float64 copies of each cloud at most
