"""What every picture shares (report/canvas.py, report/heatmap.py): wall distances keep the
nearest cell of each block, thinned points keep one a square, density shades by occupied share,
a picture shows the part of the grid that holds walls."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.report.canvas import extent, shade, thinned, window
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


def _walls_in(shape, rows, cols, full=True, footprint=None, features=()):
    """A stand-in result on a 0.1 m grid with origin (10, 20): truth walls on ``rows`` x
    ``cols`` (slices), none on the map's side; one detector whose truth has the ``features``
    (x, y metres) and whose map has none."""
    truth = np.zeros(shape, bool)
    truth[rows, cols] = True
    sides = SimpleNamespace(truth=SimpleNamespace(xy=np.array(features).reshape(-1, 2)),
                            map=SimpleNamespace(xy=np.zeros((0, 2))))
    return SimpleNamespace(grid=MetricGrid(0.1, (10.0, 20.0, 0.0), shape), truth_occupied=truth,
                           map_occupied=np.zeros(shape, bool), full=full,
                           overlap=SimpleNamespace(footprint=footprint),
                           detectors={"harris": sides})


def test_a_picture_shows_the_walls_with_a_margin():
    """Walls on rows 400-599 and columns 300-399 of a 1000 x 1000 grid of 0.1 m: shown with a
    margin of 5 % of the box's larger side (10 cells, 1 m: the least margin too); at the grid's
    corner the window stops at the grid; an empty grid is shown whole."""
    result = _walls_in((1000, 1000), slice(400, 600), slice(300, 400))
    assert window(result) == (slice(390, 610), slice(290, 410))
    left, right, bottom, top = extent(result, 1, window(result))
    np.testing.assert_allclose([left, right, bottom, top], [39.0, 51.0, 59.0, 81.0])
    wide = _walls_in((1000, 1000), slice(0, 10), slice(0, 600))  # margin 30 cells, cut at 0
    assert window(wide) == (slice(0, 40), slice(0, 630))
    assert window(_walls_in((50, 60), slice(0, 0), slice(0, 0))) == (slice(0, 50), slice(0, 60))


def test_a_partial_maps_footprint_is_shown_whole():
    """Scored within the map's footprint: the footprint's cells are shown with the walls."""
    footprint = np.zeros((1000, 1000), bool)
    footprint[700:800, 700:900] = True
    result = _walls_in((1000, 1000), slice(400, 600), slice(300, 400), full=False,
                       footprint=footprint)
    assert window(result) == (slice(370, 830), slice(270, 930))  # margin: 5 % of 600


def test_a_feature_off_the_walls_is_shown_too():
    """A truth feature at (20.05, 100.05) m, the centre of row 199 and column 100, beyond the
    walls of rows 400-599: shown, with the margin of the box that holds both."""
    result = _walls_in((1000, 1000), slice(400, 600), slice(300, 400),
                       features=[(20.05, 100.05)])
    assert window(result) == (slice(178, 621), slice(79, 421))  # margin: 21 cells, 5 % of 401
