"""SIFT's acceptance rule: keypoints within the threshold match only if their descriptors are
alike (L2 distance at most the descriptors' length, 512: cosine >= 0.5)."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.features import Features, detect
from pcmapq.features.sift import DESCRIPTOR_NORM, Params
from pcmapq.match import match
from pcmapq.raster import draw
from testkit import synth


def unit(*weights: float) -> np.ndarray:
    """A non-negative descriptor of length 512 along the first few of its 128 axes."""
    d = np.zeros(128, np.float32)
    d[: len(weights)] = weights
    return (DESCRIPTOR_NORM * d / np.linalg.norm(d)).astype(np.float32)


def keypoints(xy, descriptors) -> Features:
    """Strong keypoints at ``xy`` (N, 2) metres with the given (N, 128) descriptors."""
    xy = np.asarray(xy, np.float64).reshape(-1, 2)
    return Features(xy=xy, strength=np.ones(len(xy)), strong=np.ones(len(xy), bool),
                    descriptors=np.asarray(descriptors, np.float32).reshape(-1, 128))


def at_angle(degrees: float) -> np.ndarray:
    """A descriptor at ``degrees`` from ``unit(1)``: L2 distance 2 * 512 * sin(degrees / 2)."""
    t = np.radians(degrees)
    return unit(np.cos(t), np.sin(t))


def test_gate_is_the_descriptor_length():
    assert Params().descriptor_gate == DESCRIPTOR_NORM == 512.0
    assert np.linalg.norm(at_angle(60.0) - unit(1)) == pytest.approx(512.0, rel=1e-6)


@pytest.mark.parametrize(("degrees", "matched"), [(0.0, 1), (30.0, 1), (59.0, 1), (61.0, 0),
                                                  (90.0, 0)])
def test_alike_within_the_threshold_match_unlike_do_not(degrees, matched):
    truth = keypoints([[0.0, 0.0]], [unit(1)])
    map_ = keypoints([[0.1, 0.0]], [at_angle(degrees)])
    m = match("sift", truth, map_, threshold=0.5)
    assert m.matched == m.matched_map == matched


def test_swapped_descriptors_are_not_matched():
    """Two places 3 m apart that look different: a map with each place where it belongs but
    looking like the other matches nothing; the same map with the right looks matches both."""
    a, b = unit(1, 1, 0, 0), unit(0, 0, 1, 1)  # disjoint: as unlike as possible
    truth = keypoints([[0.0, 0.0], [3.0, 0.0]], [a, b])
    swapped = match("sift", truth, keypoints([[0.05, 0.0], [3.05, 0.0]], [b, a]))
    assert (swapped.quality, swapped.precision) == (0.0, 0.0)
    right = match("sift", truth, keypoints([[0.05, 0.0], [3.05, 0.0]], [a, b]))
    assert (right.quality, right.precision) == (1.0, 1.0)
    np.testing.assert_allclose(right.displacement, [[0.05, 0.0], [0.05, 0.0]])


def test_a_farther_alike_keypoint_beats_a_nearer_unlike_one():
    truth = keypoints([[0.0, 0.0]], [unit(1)])
    map_ = keypoints([[0.05, 0.0], [0.4, 0.0]], [at_angle(80.0), at_angle(10.0)])
    m = match("sift", truth, map_, threshold=0.5)
    np.testing.assert_array_equal(m.map_idx, [1])
    np.testing.assert_allclose(m.displacement, [[0.4, 0.0]])
    # cost: mean of 0.4 m / 0.5 m and the descriptor distance over the gate
    expected = 0.5 * (0.8 + 2 * np.sin(np.radians(5.0)))
    np.testing.assert_allclose(m.cost, [expected], rtol=1e-5)


def test_same_keypoints_of_a_redrawn_plan_are_well_within_the_gate():
    """The gate's calibration: the plan drawn half a cell shifted, and turned 23 degrees and
    warped back, keeps every matched pair's descriptors within 0.6 of the gate (measured at
    most 0.52). Descriptors with SIFT's dominant orientation reached 0.9-1.3 of it."""
    plan = synth.building_plan(0)
    grid = synth.plan_grid(plan, 0.05)
    truth = detect("sift", synth.render(plan, grid) == synth.OCCUPIED, grid)
    ox, oy, _ = grid.origin
    shifted = MetricGrid(0.05, (ox + 0.025, oy + 0.025, 0.0), grid.shape)
    tf = Similarity2D(yaw=np.radians(23.0))
    turned = synth.transform_segments(plan, tf)
    tgrid = synth.plan_grid(turned, 0.05)
    state = np.where(synth.render(turned, tgrid) == synth.OCCUPIED, draw.OCCUPIED, draw.FREE)
    maps = [(synth.render(plan, shifted) == synth.OCCUPIED, shifted),
            (draw.warp_state(state, tgrid, tf.inverse(), grid) == draw.OCCUPIED, grid)]
    for occ, g in maps:
        map_ = detect("sift", occ, g)
        m = match("sift", truth, map_)
        assert m.quality >= 0.95 and m.precision >= 0.95
        desc = np.linalg.norm(truth.descriptors[m.truth_idx] - map_.descriptors[m.map_idx],
                              axis=1)
        assert desc.max() < 0.6 * Params().descriptor_gate, desc.max()
