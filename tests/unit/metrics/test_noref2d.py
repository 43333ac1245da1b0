"""2D no-reference figures (after Filatov et al. 2017) on rasters with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.grid import MetricGrid
from pcmapq.metrics import noref2d

RES = 0.05


def _room() -> np.ndarray:
    """A closed 11 x 6 m room: 0.15 m walls around free space, unknown outside."""
    s = np.full((200, 300), UNKNOWN, np.int8)
    s[40:160, 40:260] = OCCUPIED
    s[43:157, 43:257] = FREE
    return s


def _scores(s: np.ndarray) -> noref2d.GridScores:
    return noref2d.grid_scores(s, MetricGrid(RES, (0.0, 0.0, 0.0), s.shape))


def test_closed_room():
    got = _scores(_room())
    assert (got.occupied_cells, got.free_cells) == (120 * 220 - 114 * 214, 114 * 214)
    assert got.occupied_free_ratio == pytest.approx(got.occupied_cells / got.free_cells)
    assert got.corners == 4
    assert got.enclosed_areas == 1
    assert got.enclosed_area_m2 == pytest.approx(114 * 214 * RES * RES)


def test_a_walled_in_pocket_adds_an_area_corners_and_occupied_cells():
    room = _scores(_room())
    s = _room()
    s[80:83, 43:150] = OCCUPIED   # a doubled wall that closes a pocket
    s[43:83, 147:150] = OCCUPIED
    got = _scores(s)
    assert got.enclosed_areas == 2
    assert got.corners > room.corners
    assert got.occupied_free_ratio > room.occupied_free_ratio
    areas = noref2d.enclosed_areas(s, RES)
    assert areas[1] == pytest.approx(37 * 104 * RES * RES)


def test_an_opening_onto_unknown_or_the_edge_is_not_enclosed():
    s = _room()
    s[40:43, 100:120] = UNKNOWN
    assert _scores(s).enclosed_areas == 0
    edge = _room()[43:, :]          # the room's top wall cut away by the map's edge
    assert noref2d.enclosed_areas(edge, RES).size == 0


def test_a_diagonal_wall_closes_an_area_and_tiny_gaps_are_ignored():
    s = np.full((60, 60), FREE, np.int8)
    s[0, :] = s[-1, :] = s[:, 0] = s[:, -1] = OCCUPIED
    rows = np.arange(60)
    s[rows, rows] = OCCUPIED        # 8-connected diagonal: two triangles
    assert noref2d.enclosed_areas(s, RES).size == 2
    s[30, 40] = OCCUPIED            # a one-cell hole inside a block of wall is not an area
    s[29:32, 9:12] = OCCUPIED
    s[30, 10] = FREE
    assert noref2d.enclosed_areas(s, RES).size == 2
    assert noref2d.enclosed_areas(s, RES, min_area_m2=0.0).size == 3


def test_no_free_cells():
    s = np.full((10, 10), UNKNOWN, np.int8)
    s[5, :] = OCCUPIED
    assert noref2d.occupied_free(s) == (10, 0, None)
