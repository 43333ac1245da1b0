"""Block pooling of rasters for pictures (pcmapq.raster.pool), with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.raster.pool import max_pool, min_pool


def test_max_pool_keeps_a_single_wall_cell_in_its_block():
    """7 x 8 cells in 3 x 3 blocks: 3 x 3 blocks, the last row and column partial; the one wall
    cell (row 6, column 7, in the partial corner block) makes that block a wall, no other."""
    walls = np.zeros((7, 8), bool)
    walls[6, 7] = True
    pooled = max_pool(walls, 3)
    assert pooled.dtype == bool and pooled.shape == (3, 3)
    assert np.argwhere(pooled).tolist() == [[2, 2]]


def test_max_pool_keeps_every_one_cell_wall():
    """A wall one cell thin, on a diagonal and along a row, marks every block it crosses."""
    walls = np.zeros((100, 100), bool)
    walls[np.arange(100), np.arange(100)] = True
    walls[41, :] = True
    pooled = max_pool(walls, 4)
    expected = np.eye(25, dtype=bool)
    expected[41 // 4, :] = True
    np.testing.assert_array_equal(pooled, expected)


def test_max_pool_equals_padding_and_reshaping():
    """Against the padded reshape-max, on uint8 and float32 values."""
    rng = np.random.default_rng(3)
    for values in (rng.integers(0, 255, (53, 38), dtype=np.uint8),
                   rng.random((53, 38), dtype=np.float32)):
        f = 5
        padded = np.pad(values, ((0, 2), (0, 2)), constant_values=values.min())
        expected = padded.reshape(11, f, 8, f).max(axis=(1, 3))
        pooled = max_pool(values, f)
        assert pooled.dtype == values.dtype
        np.testing.assert_array_equal(pooled, expected)


def test_min_pool_ignores_nan():
    """Distances (float32) on 2 x 4 cells in 2 x 2 blocks: the smallest number of each block;
    a block of NaN alone stays NaN."""
    nan = np.nan
    values = np.array([[0.5, nan, nan, nan],
                       [nan, 0.25, nan, nan]], np.float32)
    np.testing.assert_array_equal(min_pool(values, 2), np.array([[0.25, nan]], np.float32))


def test_factor_one_is_the_raster_itself():
    walls = np.ones((3, 2), bool)
    assert max_pool(walls, 1) is walls and min_pool(walls.astype(np.float32), 1).shape == (3, 2)
    with pytest.raises(ValueError, match="at least 1"):
        max_pool(walls, 0)
