"""Resampling onto finer or coarser cells: the cells a wall covers are those its area fractions
give, found in bytes where each new cell lies in one old one, and a known answer."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.grid import MetricGrid
from pcmapq.features.resample import covered, resample

pytestmark = pytest.mark.unit


def test_covered_known_answer() -> None:
    """Cells of 0.05 m onto 0.025 m: each wall cell becomes a 2 x 2 block, in place."""
    mask = np.zeros((3, 4), dtype=bool)
    mask[0, 1] = mask[2, 3] = True
    got, grid = covered(mask, MetricGrid(0.05, (1.0, -2.0, 0.3), mask.shape), 0.025)
    assert got.dtype == np.uint8 and grid.shape == (6, 8)
    assert grid.origin == (1.0, -2.0, 0.3) and grid.resolution == 0.025
    expected = np.zeros((6, 8), dtype=np.uint8)
    expected[0:2, 2:4] = expected[4:6, 6:8] = 1
    assert np.array_equal(got, expected)


@pytest.mark.parametrize("resolution", [0.05, 0.025, 0.0125, 0.02, 0.03, 0.1])
def test_covered_is_where_a_wall_has_area(resolution: float) -> None:
    """Finer by a whole factor, the same, finer or coarser by another: the cells with any wall
    area in them, as the area fractions of :func:`resample` give them."""
    rng = np.random.default_rng(3)
    mask = rng.random((37, 53)) < 0.2
    grid = MetricGrid(0.05, (0.0, 0.0, 0.0), mask.shape)
    got, work = covered(mask, grid, resolution)
    frac, frac_grid = resample(mask, grid, resolution)
    assert work == frac_grid
    assert np.array_equal(got, (frac > 1e-6).astype(np.uint8))
