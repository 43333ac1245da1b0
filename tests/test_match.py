"""One-to-one optimal matching, hysteresis, and the quality arithmetic."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.errors import InputError
from pcmapq.features.base import Features
from pcmapq.match import assign, match


def points(xy, strong=None) -> Features:
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    strong = np.ones(len(xy), bool) if strong is None else np.asarray(strong, bool)
    return Features(xy=xy, strength=np.ones(len(xy)), strong=strong)


def test_optimal_not_greedy():
    # greedy closest-first pairs truth 0 with map 0 (0.2 m) and leaves truth 1 alone;
    # the optimum pairs truth 0 - map 1 and truth 1 - map 0 (0.25 m each)
    truth = points([[0.0, 0.0], [0.45, 0.0]])
    map_ = points([[0.2, 0.0], [-0.25, 0.0]])
    m = match("harris", truth, map_, threshold=0.5)
    assert m.matched == 2 and m.quality == 1.0 and m.precision == 1.0
    np.testing.assert_array_equal(m.truth_idx, [0, 1])
    np.testing.assert_array_equal(m.map_idx, [1, 0])
    np.testing.assert_allclose(m.displacement, [[-0.25, 0.0], [-0.25, 0.0]])


def test_one_close_pair_beats_two_stretched_ones():
    # matching both would pair 0.35 m and 0.4 m apart; one pair 0.05 m apart is the better map
    truth = points([[0.0, 0.0], [0.4, 0.0]])
    map_ = points([[0.05, 0.0], [-0.35, 0.0]])
    m = match("harris", truth, map_, threshold=0.5)
    np.testing.assert_array_equal(m.truth_idx, [0])
    np.testing.assert_array_equal(m.map_idx, [0])


def test_least_cost_among_maximum_matchings():
    truth = points([[0.0, 0.0], [1.0, 0.0]])
    map_ = points([[0.9, 0.0], [0.1, 0.0]])
    m = match("harris", truth, map_, threshold=1.0)
    np.testing.assert_array_equal(m.map_idx, [1, 0])
    np.testing.assert_allclose(m.cost, [0.1, 0.1])  # 0.1 m over a 1 m threshold


def test_threshold_respected_and_one_to_one():
    rng = np.random.default_rng(1)
    truth = points(rng.uniform(0, 10, (200, 2)))
    map_ = points(truth.xy + rng.normal(0, 0.3, truth.xy.shape))
    m = match("harris", truth, map_, threshold=0.5)
    assert np.all(np.linalg.norm(m.displacement, axis=1) <= 0.5)
    assert len(np.unique(m.truth_idx)) == len(m.truth_idx) == m.matched
    assert len(np.unique(m.map_idx)) == len(m.map_idx)
    np.testing.assert_allclose(m.displacement, map_.xy[m.map_idx] - truth.xy[m.truth_idx])


def test_quality_precision_f1_arithmetic():
    truth = points([[0, 0], [5, 0], [10, 0], [15, 0]])
    map_ = points([[0.1, 0], [5.1, 0], [20, 0]])
    m = match("harris", truth, map_)
    assert (m.truth_features, m.map_features, m.matched, m.matched_map) == (4, 3, 2, 2)
    assert m.quality == pytest.approx(0.5) and m.precision == pytest.approx(2 / 3)
    assert m.f1 == pytest.approx(2 * 0.5 * (2 / 3) / (0.5 + 2 / 3))
    np.testing.assert_array_equal(m.missing, [2, 3])
    np.testing.assert_array_equal(m.extra, [2])


def test_hysteresis():
    # a weak map feature confirms a strong truth feature
    m = match("harris", points([[0, 0]]), points([[0.1, 0]], strong=[False]))
    assert m.quality == 1.0 and m.map_features == 0 and m.precision is None
    # two weak features never match each other
    m = match("harris", points([[0, 0]], [False]), points([[0.1, 0]], [False]))
    assert len(m.truth_idx) == 0 and m.truth_features == 0
    # a strong-strong pair is preferred to a strong-weak one
    truth = points([[0, 0], [0.2, 0]], strong=[True, False])
    m = match("harris", truth, points([[0.15, 0]]))
    np.testing.assert_array_equal(m.truth_idx, [0])
    assert m.quality == 1.0 and m.precision == 1.0


def test_empty_inputs():
    """A ratio with nothing to count is undefined (None), not 0; so is f1 then."""
    empty = points(np.zeros((0, 2)))
    expected = [(None, None, "no strong truth feature; no strong map feature"),
                (None, 0.0, "no strong truth feature"),
                (0.0, None, "no strong map feature")]
    pairs = ((empty, empty), (empty, points([[0, 0]])), (points([[0, 0]]), empty))
    for (truth, map_), (quality, precision, note) in zip(pairs, expected, strict=True):
        m = match("harris", truth, map_)
        assert m.matched == 0 and m.displacement.shape == (0, 2)
        assert (m.quality, m.precision, m.f1) == (quality, precision, None)
        assert m.note() == note
    # both defined and both 0: f1 is 0, no note
    m = match("harris", points([[0, 0]]), points([[5, 0]]))
    assert (m.quality, m.precision, m.f1, m.note()) == (0.0, 0.0, 0.0, None)
    # only weak truth features: undefined, and the note says where
    m = match("harris", points([[0, 0]], [False]), points([[0.1, 0]]))
    assert m.quality is None and m.precision == 1.0 and m.f1 is None
    assert m.note("inside the footprint") == "no strong truth feature inside the footprint"


def test_assign_components():
    # two independent components, one needing the assignment, one a single pair
    i = np.array([0, 0, 1, 5])
    j = np.array([0, 1, 0, 7])
    chosen = assign(i, j, np.array([0.1, 0.3, 0.2, 1.0]), np.full(4, 2))
    np.testing.assert_array_equal(chosen, [False, True, True, True])


def test_unknown_detector():
    with pytest.raises(InputError):
        match("nope", points([[0, 0]]), points([[0, 0]]))
