"""Free space as evidence of a pose (pcmapq.align.free_space): a room and a solid block of the
same outline fit a room's walls equally; only the room's free space tells them apart."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align import align
from pcmapq.align.free_space import FreeSpace
from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import outline
from pcmapq.core.transform import Similarity2D

RES = 0.05
#: The truth: 20 x 10 m; a 4 x 3 m room with a 1 m door gap in its south wall (walls 0.1 m)
#: centred at ROOM, and a solid 4 x 3 m block (a kitchen run drawn filled) centred at BLOCK.
ROOM, BLOCK = np.array([5.0, 5.0]), np.array([15.0, 5.0])


def _truth() -> tuple[MetricGrid, np.ndarray]:
    grid = MetricGrid(RES, (0.0, 0.0, 0.0), (200, 400))
    xy = grid.pixels_to_xy(np.stack(np.meshgrid(np.arange(400), np.arange(200)), -1)
                           .reshape(-1, 2)).reshape(200, 400, 2)
    d = np.abs(xy - ROOM)
    walls = (np.maximum(d[..., 0] / 2.0, d[..., 1] / 1.5) <= 1.0) & \
            ((d[..., 0] >= 1.9) | (d[..., 1] >= 1.4))
    door = (d[..., 0] < 0.5) & (xy[..., 1] < ROOM[1])
    block = np.all(np.abs(xy - BLOCK) <= [2.0, 1.5], axis=-1)
    return grid, (walls & ~door) | block


def _room_map(yaw_deg: float, shift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The room as a robot maps it, in a frame turned by ``yaw_deg`` and moved by ``shift``:
    its walls (the door's wall piece missing) and its free cells, (N, 2) metres each."""
    x, y = np.meshgrid(np.arange(-2.0, 2.0 + 1e-9, RES), np.arange(-1.5, 1.5 + 1e-9, RES))
    x, y = x.ravel(), y.ravel()
    edge = (np.abs(x) > 1.95 - 1e-9) | (np.abs(y) > 1.45 - 1e-9)
    door = (np.abs(x) < 0.5) & (y < 0)
    walls = np.column_stack([x, y])[edge & ~door]
    free = np.column_stack([x, y])[~edge]
    c, s = np.cos(np.radians(yaw_deg)), np.sin(np.radians(yaw_deg))
    turn = np.array([[c, -s], [s, c]])
    return walls @ turn.T + shift, free @ turn.T + shift


def _centre_error(tf: Similarity2D, shift: np.ndarray, centre: np.ndarray) -> float:
    """Metres between where ``tf`` puts the map's room centre and ``centre``."""
    return float(np.linalg.norm(tf.apply(shift.reshape(1, 2))[0] - centre))


def test_free_space_places_the_room_not_the_block():
    """Turned by 150 degrees, the walls alone land on the block (fitness 1.0 there too)."""
    grid, solid = _truth()
    truth_xy = grid.cell_centres(outline(solid, 0.1 / RES))
    shift = np.array([1.0, 1.0])
    walls, free = _room_map(150.0, shift)
    space = FreeSpace(free, solid, np.ones_like(solid), grid)
    placed = align(walls, truth_xy, free=space)
    assert _centre_error(placed.transform, shift, ROOM) < 0.1
    assert placed.contradiction < 0.02 and placed.free_on_truth > 0.99
    # the block fits the walls as well: placed there, nearly all free space lies inside it
    back = Similarity2D(0.0, 0.0, np.radians(-150.0)).compose(
        Similarity2D(-shift[0], -shift[1], 0.0))
    on_block = Similarity2D(BLOCK[0], BLOCK[1], 0.0).compose(back)
    clear = space.clear(walls, RES)
    assert space.contradiction(clear, on_block) > 0.9
    assert align(walls, truth_xy, init=on_block, refine=False).fitness == pytest.approx(
        align(walls, truth_xy, init=placed.transform, refine=False).fitness, abs=0.05)


def test_without_free_space_the_result_has_none():
    grid, solid = _truth()
    truth_xy = grid.cell_centres(outline(solid, 0.1 / RES))
    walls, _ = _room_map(30.0, np.array([-3.0, 7.0]))
    placed = align(walls, truth_xy)
    assert placed.contradiction is None and placed.free_on_truth is None


def test_free_space_off_the_truth_is_neither_evidence():
    """Free points off the truth's known cells count in neither share's numerator."""
    grid, solid = _truth()
    known = np.zeros_like(solid)
    known[:, :200] = True  # the truth knows its west half only
    space = FreeSpace(np.zeros((0, 2)), solid, known | solid, grid)
    points = np.array([[5.0, 5.0], [2.0, 8.0], [15.0, 5.0], [15.5, 5.5], [18.0, 9.0]])
    tf = Similarity2D()
    # on known: (5,5) free room inside, (2,8) free, (15,5) and (15.5,5.5) block: 4 of 5
    assert space.on_truth(points, tf) == pytest.approx(0.8)
    assert space.contradiction(points, tf) == pytest.approx(0.5)
