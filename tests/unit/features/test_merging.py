"""Collinear fragments merged into walls (features/merging.py): known layouts."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.grid import MetricGrid
from pcmapq.features.merging import merge
from pcmapq.features.segments import wall_test

#: The Hough detector's defaults: 15 degrees, 0.15 m across, 0.2 m along, bridges of 1.5 m.
ANGLE, OFFSET, GAP, BRIDGE = 15.0, 0.15, 0.2, 1.5
#: A 10 m x 10 m grid of 0.05 m cells from (-5, -5).
GRID = MetricGrid(0.05, (-5.0, -5.0, 0.0), (200, 200))


def canonical(seg: np.ndarray) -> np.ndarray:
    """Segments with the smaller endpoint first, sorted."""
    seg = np.asarray(seg, dtype=np.float64).reshape(-1, 4).copy()
    flip = (seg[:, 0] > seg[:, 2]) | ((seg[:, 0] == seg[:, 2]) & (seg[:, 1] > seg[:, 3]))
    seg[flip] = seg[flip][:, [2, 3, 0, 1]]
    return seg[np.lexsort(seg.T[::-1])]


def solid_along_x(x0: float, x1: float) -> object:
    """A wall test whose wall is the line y = 0 from x0 to x1 (3 cells thick)."""
    image = np.zeros(GRID.shape, np.float32)
    uv = np.round(GRID.xy_to_pixels(np.array([[x0, 0.0], [x1, 0.0]]))).astype(int)
    image[uv[0, 1] - 1:uv[0, 1] + 2, uv[0, 0]:uv[1, 0] + 1] = 1.0
    return wall_test(image, GRID, 0.5)


def test_fragments_within_the_gap_join_and_a_farther_one_does_not():
    seg = np.array([[0.0, 0.0, 1.0, 0.0], [1.1, 0.0, 2.0, 0.0], [2.5, 0.0, 3.0, 0.0]])
    got = canonical(merge(seg, ANGLE, OFFSET, GAP))
    assert got == pytest.approx(np.array([[0.0, 0.0, 2.0, 0.0], [2.5, 0.0, 3.0, 0.0]]))


def test_a_gap_where_the_wall_is_solid_is_bridged():
    seg = np.array([[0.0, 0.0, 1.0, 0.0], [1.1, 0.0, 2.0, 0.0], [2.5, 0.0, 3.0, 0.0]])
    got = canonical(merge(seg, ANGLE, OFFSET, GAP, solid_along_x(0.0, 3.0), BRIDGE))
    assert got == pytest.approx(np.array([[0.0, 0.0, 3.0, 0.0]]))
    # solid only up to 2.2 m: the gap to 2.5 m is open, the fragment stays apart
    got = canonical(merge(seg, ANGLE, OFFSET, GAP, solid_along_x(0.0, 2.2), BRIDGE))
    assert len(got) == 2
    # a gap longer than the largest bridge stays open, solid or not
    far = np.array([[0.0, 0.0, 1.0, 0.0], [2.6, 0.0, 3.0, 0.0]])
    assert len(merge(far, ANGLE, OFFSET, GAP, solid_along_x(0.0, 3.0), BRIDGE)) == 2


def test_a_parallel_wall_or_a_turned_one_stays_apart():
    seg = np.array([[0.0, 0.0, 2.0, 0.0],
                    [0.0, 0.5, 2.0, 0.5],  # 0.5 m across: the other side of a thin wall
                    [2.05, 0.0, 2.05 + np.cos(np.radians(20)), np.sin(np.radians(20))]])
    got = canonical(merge(seg, ANGLE, OFFSET, GAP))
    assert got == pytest.approx(canonical(seg))


def test_the_merged_line_is_fitted_to_the_fragments_and_spans_them():
    """Two fragments 0.1 m apart across, weighted by length: the line lies at the weighted
    mean offset (a 3 m fragment at y = 0 and a 1 m one at y = 0.1: y = 0.025), and the merged
    segment spans both."""
    seg = np.array([[0.0, 0.0, 3.0, 0.0], [3.1, 0.1, 4.1, 0.1]])
    (x0, y0, x1, y1), = canonical(merge(seg, ANGLE, OFFSET, GAP))
    assert (x0, x1) == pytest.approx((0.0, 4.1), abs=0.01)
    assert abs(np.degrees(np.arctan2(y1 - y0, x1 - x0))) < 2.0
    assert 0.5 * (y0 + y1) == pytest.approx(0.025, abs=0.02)


def test_merging_is_repeatable_whatever_the_input_order():
    rng = np.random.default_rng(5)
    x = np.sort(rng.uniform(0, 4, 40)).reshape(-1, 2)  # 20 fragments along y = 0
    seg = np.column_stack([x[:, 0], np.zeros(20), x[:, 1], np.zeros(20)])
    once = canonical(merge(seg, ANGLE, OFFSET, 0.5))
    assert np.array_equal(once, canonical(merge(seg[::-1].copy(), ANGLE, OFFSET, 0.5)))
    assert np.array_equal(once, canonical(merge(seg, ANGLE, OFFSET, 0.5)))
