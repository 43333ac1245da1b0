"""One-to-one optimal matching, hysteresis, and the quality arithmetic."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.errors import InputError
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


def test_hough_candidates_all_pairs_the_rule_allows():
    """The segment pairs tested are prefiltered by distance; none the rule allows is lost: the
    candidates equal the rule applied to every pair (short and long segments, turned up to
    15 degrees, offsets up to twice the threshold)."""
    from pcmapq.features import hough
    from pcmapq.features.segments import directions

    rng = np.random.default_rng(3)

    def segments(n: int) -> np.ndarray:
        mid = rng.uniform(0, 20, (n, 2))
        angle = rng.choice([0.0, np.pi / 2], n) + np.radians(rng.uniform(-15, 15, n))
        half = rng.choice([0.2, 1.0, 6.0], n)[:, None] * np.column_stack([np.cos(angle),
                                                                          np.sin(angle)])
        return np.hstack([mid - half, mid + half])

    truth_seg = segments(300)
    map_seg = np.vstack([truth_seg + rng.uniform(-1.0, 1.0, (300, 4)), segments(300)])

    def features(seg: np.ndarray) -> Features:
        length = directions(seg)[1]
        return Features(0.5 * (seg[:, :2] + seg[:, 2:]), length, length > 1.0, segments=seg)

    params, threshold = hough.Params(), 0.5
    truth_f, map_f = features(truth_seg), features(map_seg)
    i, j, cost, disp = hough.candidates(truth_f, map_f, threshold, params)
    # the rule on every pair
    dt, lt = directions(truth_seg)
    dm, _ = directions(map_seg)
    ii, jj = np.nonzero(np.abs(dt @ dm.T) >= np.cos(np.radians(params.max_angle)))
    ii, jj = ii[truth_f.strong[ii] | map_f.strong[jj]], jj[truth_f.strong[ii] | map_f.strong[jj]]
    mt, mm = truth_f.xy[ii], map_f.xy[jj]
    nt, nm = np.column_stack([-dt[ii, 1], dt[ii, 0]]), np.column_stack([-dm[jj, 1], dm[jj, 0]])
    off = np.maximum(np.abs(np.sum((mm - mt) * nm, 1)), np.abs(np.sum((mm - mt) * nt, 1)))
    a = np.sum((map_seg[jj, :2] - mt) * dt[ii], 1)
    b = np.sum((map_seg[jj, 2:] - mt) * dt[ii], 1)
    overlap = np.minimum(np.maximum(a, b), 0.5 * lt[ii]) - np.maximum(np.minimum(a, b),
                                                                      -0.5 * lt[ii])
    keep = (overlap > 0) & (off <= threshold)
    assert keep.sum() > 100
    assert np.array_equal(i, ii[keep]) and np.array_equal(j, jj[keep])
    assert np.allclose(cost, off[keep] / threshold)
