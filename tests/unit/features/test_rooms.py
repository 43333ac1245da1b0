"""Rooms and doors of free space, on plans with known rooms and doors."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.features.room_segmentation import (
    Params,
    segment,
    without_furniture,
    without_wall_furniture,
)

RES = 0.05


def cells(metres: float) -> int:
    return int(round(metres / RES))


def plan(rooms: int = 3, room_w: float = 4.0, depth: float = 5.0, door: float = 0.9,
         doors: tuple[bool, ...] | None = None, walls: tuple[bool, ...] | None = None
         ) -> np.ndarray:
    """Free cells (bool) of a row of ``rooms`` rooms ``room_w`` x ``depth`` metres behind walls
    0.1 m thick; between rooms ``i`` and ``i + 1`` a wall (``walls[i]``) with a door ``door``
    metres wide in its middle (``doors[i]``)."""
    doors = (True,) * (rooms - 1) if doors is None else doors
    walls = (True,) * (rooms - 1) if walls is None else walls
    wall, margin = cells(0.1), cells(1.0)
    width, height = rooms * cells(room_w) + (rooms + 1) * wall, cells(depth) + 2 * wall
    free = np.zeros((height + 2 * margin, width + 2 * margin), dtype=bool)
    top, left = margin + wall, margin + wall
    free[top:top + cells(depth), left:left + width - 2 * wall] = True
    for i in range(rooms - 1):
        x = left + (i + 1) * cells(room_w) + i * wall
        if walls[i]:
            free[top:top + cells(depth), x:x + wall] = False
            if doors[i]:
                mid = top + cells(depth) // 2
                free[mid - cells(door) // 2:mid + cells(door) // 2, x:x + wall] = True
    return free


def test_rooms_and_doors_of_a_row_of_rooms():
    rooms = segment(plan(), RES)
    assert len(rooms) == 3
    np.testing.assert_allclose(rooms.area_m2, 4.0 * 5.0, rtol=0.03)
    assert sorted(map(tuple, rooms.doors.tolist())) == [(0, 1), (1, 2)]
    np.testing.assert_allclose(rooms.door_width_m, 0.9, atol=0.1)
    # centroids left to right, 4.1 m apart; clearance: half the room's shorter side
    order = np.argsort(rooms.centroid[:, 1])
    np.testing.assert_allclose(np.diff(rooms.centroid[order, 1]) * RES, 4.1, atol=0.1)
    np.testing.assert_allclose(rooms.clearance_m, 2.0, atol=0.1)


def test_a_wall_removed_merges_two_rooms():
    rooms = segment(plan(walls=(True, False)), RES)
    assert len(rooms) == 2
    np.testing.assert_allclose(np.sort(rooms.area_m2), [20.0, 8.1 * 5.0], rtol=0.03)
    assert len(rooms.doors) == 1


def test_a_door_closed_leaves_the_rooms_without_a_door_between_them():
    rooms = segment(plan(doors=(True, False)), RES)
    assert len(rooms) == 3
    assert len(rooms.doors) == 1


def test_a_wide_opening_is_no_door():
    """An opening nearly as wide as the rooms joins them: one room."""
    rooms = segment(plan(rooms=2, door=4.0), RES)
    assert len(rooms) == 1


def two_squares(gap: int) -> np.ndarray:
    """Free cells of two 19 x 19-cell rooms side by side, peak clearance 10 cells, with an
    opening of ``gap`` cells in the middle of the one-cell wall between them: its clearance is
    (gap + 1) / 2 cells."""
    free = np.zeros((21, 41), dtype=bool)
    free[1:20, 1:20] = free[1:20, 21:40] = True
    free[10 - gap // 2:10 + gap // 2 + 1, 20] = True
    return free


@pytest.mark.parametrize("resolution", [0.05, 0.1, 0.2])
@pytest.mark.parametrize(("gap", "count"), [(11, 2), (13, 1), (15, 1)],
                         ids=["0.6 of the peak", "exactly door_ratio", "0.8 of the peak"])
def test_an_opening_of_exactly_door_ratio_joins_two_rooms(gap, count, resolution):
    """A passage whose clearance is door_ratio (0.7) of the rooms' peak, in whole cells, joins
    them as one narrower than that does not, on every cell size (float32 rounding aside)."""
    bare = Params(furniture_m=0.0, min_room_m2=0.0, min_space_m2=0.0)
    assert len(segment(two_squares(gap), resolution, bare)) == count


def test_a_long_corridor_is_one_room():
    rooms = segment(plan(rooms=1, room_w=30.0, depth=2.0), RES)
    assert len(rooms) == 1
    assert len(rooms.doors) == 0


def test_furniture_does_not_split_a_room():
    free = plan()
    rows, cols = np.nonzero(free)
    # chairs (0.4 m squares) in the middle room and a 0.8 m table
    r0, c0 = int(rows.mean()), int(cols.mean())
    for dr, dc, side in ((-20, -20, 0.4), (20, 20, 0.4), (0, 0, 0.8)):
        free[r0 + dr:r0 + dr + cells(side), c0 + dc:c0 + dc + cells(side)] = False
    assert without_furniture(free, RES, 1.0)[r0, c0]  # the table made free
    rooms = segment(free, RES)
    assert len(rooms) == 3
    assert len(rooms.doors) == 2


def test_a_wall_piece_between_two_doors_is_no_furniture():
    """A free-standing wall longer than ``furniture_m`` stays an obstacle."""
    free = np.ones((100, 100), dtype=bool)
    free[10:12, 20:60] = False  # 2 m of wall
    free[50:55, 50:55] = False  # a 0.25 m bin
    kept = without_furniture(free, RES, 1.0)
    assert not kept[10:12, 20:60].any()
    assert kept[50:55, 50:55].all()


def test_rooms_are_the_same_from_run_to_run_and_tiny_rooms_join_a_neighbour():
    free = plan()
    first, second = segment(free, RES), segment(free, RES)
    np.testing.assert_array_equal(first.labels, second.labels)
    np.testing.assert_array_equal(first.doors, second.doors)
    assert (segment(free, RES, Params(min_room_m2=25.0)).area_m2 >= 25.0).all()


@pytest.mark.parametrize("rooms", [2, 4])
def test_labels_cover_the_free_cells_only(rooms):
    free = plan(rooms=rooms)
    found = segment(free, RES)
    assert ((found.labels > 0) == free).all()
    assert found.labels.max() == len(found) == rooms


# --- the rooms detector: walls in, rooms matched by IoU -------------------------------------

def walls_of_plan(free: np.ndarray) -> np.ndarray:
    """The wall cells of a plan made by :func:`plan`: the non-free cells next to a free one."""
    import cv2

    near = cv2.dilate(free.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    return near & ~free


def scored(truth_free: np.ndarray, map_free: np.ndarray):
    from pcmapq.core.grid import MetricGrid
    from pcmapq.features import detect
    from pcmapq.match import match

    grid = MetricGrid(RES, (0.0, 0.0, 0.0), truth_free.shape)
    t = detect("rooms", walls_of_plan(truth_free), grid)
    m = detect("rooms", walls_of_plan(map_free), grid)
    return t, m, match("rooms", t, m)


def test_the_detector_finds_the_rooms_of_the_walls_and_matches_them_all():
    t, m, found = scored(plan(), plan())
    assert len(t) == len(m) == 3
    assert found.quality == found.precision == 1.0
    # 4 x 5 m less the walls' band (0.15 m wide, its cells' share counted as wall): 0.1 m a side
    np.testing.assert_allclose(t.strength, 3.8 * 4.8, rtol=0.03)
    assert t.labels.shape == (plan().shape[0] // 2, plan().shape[1] // 2)


def test_a_wall_the_map_lacks_merges_two_rooms_and_neither_matches():
    _, m, found = scored(plan(), plan(walls=(True, False)))
    assert len(m) == 2
    assert (found.quality, found.precision) == (pytest.approx(1 / 3), pytest.approx(1 / 2))


def test_a_room_the_map_never_entered_is_missing():
    """The map has the first two rooms only: the third's place is outside its walls."""
    truth = plan()
    seen = plan()
    cut = np.flatnonzero(truth.any(axis=0))[0] + cells(2 * 4.0 + 0.2)
    seen[:, cut:] = False
    _, m, found = scored(truth, seen)
    assert len(m) == 2
    assert (found.quality, found.precision) == (pytest.approx(2 / 3), 1.0)


def third_room_cut(share: float, closed: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Walls of a plan of three rooms, and of its map ending ``share`` of the way into the
    third room, the map's wall closing it there (``closed``) or its walls simply ending (a
    partial map that saw no more); and the map's footprint, its cells to 0.3 m past the cut."""
    truth = plan()
    left = np.flatnonzero(truth.any(axis=0))[0]
    cut = left + 2 * cells(4.0) + 2 * cells(0.1) + int(round(share * cells(4.0)))
    walls = walls_of_plan(truth)
    if closed:
        seen = truth.copy()
        seen[:, cut:] = False
        map_walls = walls_of_plan(seen)
    else:
        map_walls = walls.copy()
        map_walls[:, cut:] = False
    footprint = np.zeros(truth.shape, dtype=bool)
    footprint[:, :cut + cells(0.3)] = True
    return walls, map_walls, footprint


@pytest.mark.parametrize(("closed", "counted"), [(True, True), (False, False)])
def test_a_room_seen_in_part_counts_where_the_map_drew_a_room_over_it(closed, counted):
    """70 % of the third room inside the footprint: it counts when the map drew a room of its
    own over it (a bent map's room out of place), not when the map's walls end open in it (a
    partial map that saw it through its end); the two rooms seen whole count either way."""
    from pcmapq.core.grid import MetricGrid
    from pcmapq.evaluation.scoring import inside
    from pcmapq.features import detect
    from pcmapq.features.rooms import drawn, share_inside

    walls, map_walls, footprint = third_room_cut(0.6, closed)
    grid = MetricGrid(RES, (0.0, 0.0, 0.0), walls.shape)
    t, m = detect("rooms", walls, grid), detect("rooms", map_walls, grid)
    share = share_inside(t, footprint, grid)
    assert share[:2].tolist() == [1.0, 1.0] and 0.6 < share[2] < 0.8
    assert drawn(t, m).tolist() == [True, True, closed]
    assert inside(t, footprint, grid).tolist() == [True, True, False]
    assert inside(t, footprint, grid, other=m).tolist() == [True, True, counted]


def test_a_door_the_map_closed_leaves_the_rooms_matched():
    _, _, found = scored(plan(), plan(doors=(True, False)))
    assert found.quality == found.precision == 1.0


def test_a_map_without_rooms_leaves_every_truth_room_missing():
    from pcmapq.core.grid import MetricGrid
    from pcmapq.features import detect
    from pcmapq.match import match
    from pcmapq.match.rooms import room_table

    free = plan()
    grid = MetricGrid(RES, (0.0, 0.0, 0.0), free.shape)
    truth = detect("rooms", walls_of_plan(free), grid)
    none = detect("rooms", np.zeros_like(free), grid)
    assert len(none) == 0 and none.labels.shape == truth.labels.shape
    assert match("rooms", truth, none).quality == 0.0
    assert room_table(truth, none)["counts"]["truth missing"] == 3


@pytest.mark.parametrize("map_rooms", [1, 3])
def test_a_truth_of_one_room_has_nothing_to_find(map_rooms):
    """One room in the truth (an outdoor place, a single hall): the rooms' quality, precision
    and f1 are undefined, with why, whatever the map's rooms; the counts stay."""
    hall = plan(walls=(False, False))
    t, m, found = scored(hall, hall if map_rooms == 1 else plan())
    assert (len(t), len(m)) == (1, map_rooms)
    assert (found.quality, found.precision, found.f1) == (None, None, None)
    assert found.note() == "the truth has 1 room, fewer than 2: nothing to find"
    assert (found.truth_features, found.map_features) == (1, map_rooms)


def test_a_closet_smaller_than_a_room_joins_the_room_behind_its_gap():
    """A 0.3 x 0.3 m closet behind a gap in the wall is part of the room: no door to it."""
    free = plan(rooms=1)
    rows, cols = np.nonzero(free)
    top, right = rows.min(), cols.max()
    free[top + 10:top + 16, right + 3:right + 9] = True  # the closet, behind the wall
    free[top + 12:top + 14, right + 1:right + 3] = True  # its gap through the wall
    rooms = segment(free, RES)
    assert len(rooms) == 1
    assert rooms.doors.shape == (0, 2) and (rooms.doors >= 0).all()


def corridor(cell: float = 0.1) -> tuple[np.ndarray, tuple[int, int]]:
    """Free cells of a corridor 10 m x 2 m between thin walls (0.2 m, the band every detector
    sees), and the rows of its lower and upper wall."""
    n = int(round(1.0 / cell))
    free = np.ones((4 * n, 14 * n), dtype=bool)
    low, high = n, 3 * n  # wall rows: the corridor is the rows between
    free[[low, low + 1, high, high + 1], 2 * n:12 * n + 2] = False
    free[low:high + 2, [2 * n, 2 * n + 1, 12 * n, 12 * n + 1]] = False
    return free, (low, high)


def test_a_box_against_a_wall_is_furniture_and_the_wall_behind_it_stays():
    """A 0.6 m box seen from three sides (an outline closing a pocket with the wall) and a solid
    0.5 m block against the walls of a corridor: both taken out, the walls behind them kept,
    and the corridor is one room; a 1.5 m cabinet stays."""
    cell = 0.1
    free, (low, high) = corridor(cell)
    box = np.s_[low + 2:low + 8, 40:46]  # 0.6 m square on the lower wall
    free[box] = False
    free[low + 3:low + 7, 41:45] = True  # its inside: a pocket
    free[high - 5:high, 80:85] = False  # a solid 0.5 m block under the upper wall
    free[high - 4:high, 100:115] = False  # a 1.5 m cabinet
    kept = without_wall_furniture(free, cell, Params())
    assert kept[box].all() and kept[high - 5:high, 80:85].all()
    assert not kept[low:low + 2, 20:120].any() and not kept[high:high + 2, 20:120].any()
    assert not kept[high - 4:high, 100:115].any()

    def corridor_rooms(cells: np.ndarray) -> int:
        inside = segment(cells, cell).labels[low + 2:high, 22:120]
        return len(np.unique(inside[inside > 0]))

    assert corridor_rooms(free) > 1 and corridor_rooms(kept) == 1


def test_a_short_wall_between_two_doors_is_no_wall_furniture():
    """A wall across the corridor with two doors leaves a 0.8 m piece between them: thin and
    closing no pocket, it stays, and so do the two rooms it parts."""
    cell = 0.1
    free, (low, high) = corridor(cell)
    free[low + 2:high, 70:72] = False  # a wall across the corridor at x = 7 m
    free[low + 2:low + 8, 70:72] = True  # a 0.6 m door
    free[high - 6:high, 70:72] = True  # another: 0.6 m of wall between them
    kept = without_wall_furniture(free, cell, Params())
    np.testing.assert_array_equal(kept, free)


def street(cars: int = 2) -> np.ndarray:
    """Free cells (bool) of a street 60 m long between two facades 10 m apart, both running
    off the raster (the street and what lies behind its facades are outside), with ``cars``
    parked cars 4 x 2 m: solid blocks, whose outlines close their insides off."""
    free = np.ones((cells(20.0), cells(60.0)), dtype=bool)
    free[cells(5.0), :] = free[cells(15.0), :] = False
    for k in range(cars):
        x = cells(10.0 + 15.0 * k)
        free[cells(7.0):cells(9.0), x:x + cells(4.0)] = False
    return free


def test_a_street_has_no_closed_rooms_and_nothing_to_find():
    """The insides of parked cars are closed off by their outlines (and the street between
    them by its narrows), but a street's walls are its facades: the rooms' scores are
    undefined, with why, and the counts stay."""
    t, m, found = scored(street(), street())
    assert len(t) == len(m) >= 2
    assert t.bounding < 0.25
    assert (found.quality, found.precision, found.f1) == (None, None, None)
    assert found.note() == (f"the truth has no closed rooms: {100 * t.bounding:.0f} % of its "
                            "walls bound one, fewer than 25 %: nothing to find")
    assert found.truth_features == found.map_features == found.matched == len(t)


def test_the_walls_of_a_plan_bound_its_rooms():
    t, _, found = scored(plan(), plan())
    assert t.bounding > 0.4 and found.note() is None
