"""What every picture shares (report/canvas.py, report/heatmap.py): wall distances keep the
nearest cell of each block, thinned points keep one a square, density shades by occupied share."""

from __future__ import annotations

import numpy as np

from pcmapq.report.canvas import shade, thinned
from pcmapq.report.heatmap import wall_distances


def test_wall_distances_keep_the_nearest_cell_of_each_block():
    """Truth wall in column 0 of 0.01 m cells; map cells 3 and 7 cells from it in one 10 x 10
    block, 12 cells in another: 0.03 m and 0.12 m, NaN where a block has no map cell."""
    truth, walls = np.zeros((20, 20), bool), np.zeros((20, 20), bool)
    truth[:, 0] = True
    walls[2, 3] = walls[5, 7] = walls[15, 12] = True
    np.testing.assert_allclose(wall_distances(truth, walls, 0.01, 10),
                               [[0.03, np.nan], [np.nan, 0.12]], rtol=1e-6)


def test_thinned_keeps_one_point_a_square():
    """Points 0.1 m apart in 1 m squares: one a square, the first of each, in order."""
    xy = np.array([[0.1, 0.1], [0.2, 0.1], [1.5, 0.2], [0.3, 0.9], [1.1, 1.1], [-0.5, 0.0]])
    np.testing.assert_array_equal(thinned(xy, 1.0), [0, 2, 4, 5])
    assert thinned(np.zeros((0, 2)), 1.0).shape == (0,)


def test_density_shades_by_occupied_share():
    """A 4 x 4 block with 1 and with 16 occupied cells: the lone cell shows (at least the floor),
    the full block is solid; walls mode shows both solid."""
    mask = np.zeros((4, 8), bool)
    mask[0, 0] = True
    mask[:, 4:] = True
    dens, walls = shade(mask, 4, True), shade(mask, 4, False)
    assert 0.3 <= dens[0, 0] < 0.6 and dens[0, 1] == 1.0
    np.testing.assert_array_equal(walls, [[1.0, 1.0]])
