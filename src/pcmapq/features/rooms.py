"""The rooms detector (:data:`DETECTOR`, ``rooms``): the rooms and doors of the walls
(:mod:`pcmapq.features.room_segmentation`), as features matched one to one by overlap.

It sees the walls as every detector does (their centre lines drawn as a band,
:mod:`pcmapq.features.walls`), averaged onto cells of ``cell_m``: a cell with a share of wall
is a wall, every other cell is free, and the rooms that reach the raster's edge are the
outside, not rooms. So a plan drawn with white outside and a robot map with unknown cells
beyond its walls give the same rooms, and a map's rooms are its walls' rooms whatever it marked
free. Its features are the rooms' centroids (strength: area, m^2) with their cells; a map room
and a truth room may match when their IoU is at least ``min_iou`` (the metric threshold does
not apply), the closer to 1 the better.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from pcmapq.core.bounds import on_edge
from pcmapq.core.grid import MetricGrid
from pcmapq.features.base import Candidates, Detector, Features, empty_features
from pcmapq.features.resample import resample
from pcmapq.features.room_segmentation import Params, Rooms, segment, without_wall_furniture
from pcmapq.features.walls import WallImage

__all__ = ["DETECTOR", "MIN_BOUNDING", "PIECE", "Params", "RoomOverlap", "bounding", "candidates",
           "detect", "drawn", "no_closed_rooms",
           "inside_rooms", "label_cell", "overlap", "room_cell", "room_overlap", "share_inside"]


#: A cell holding at least this share of the wall band is a wall (the band is 0.15 m wide, so
#: a wall closes every cell it crosses).
WALL_SHARE = 0.05
#: Cells a raster of rooms holds at most: a larger raster's cells are made larger (whole
#: multiples of the walls' cell), so that the rooms of a campus cost what a building's do.
MAX_CELLS = 4_000_000


#: A map room is a piece of a split truth room only when it holds at least this share of it: a
#: pocket the map closed off inside a room (a cupboard's outline, a corner behind a bin) is an
#: extra room, not a wall that splits it.
PIECE = 0.1


def room_cell(grid: MetricGrid, cell_m: float) -> float:
    """The cell the rooms of ``grid``'s raster are found on: ``cell_m``, or a whole multiple of
    the grid's cell large enough to keep the raster within :data:`MAX_CELLS`, metres."""
    rows, cols = grid.shape
    needed = grid.resolution * np.sqrt(rows * cols / MAX_CELLS)
    if needed <= cell_m:
        return cell_m
    return float(np.ceil(needed / grid.resolution) * grid.resolution)


def inside_rooms(walls: WallImage, params: Params
                 ) -> tuple[Rooms, np.ndarray, MetricGrid, np.ndarray]:
    """The rooms of the walls (see the module docstring) on cells of ``params.cell_m`` (or
    larger, :func:`room_cell`), the new number of each room (0: it reaches the raster's edge,
    the outside; else 1, 2, ...), the rooms' grid and its wall cells (bool)."""
    cell = room_cell(walls.grid, params.cell_m)
    share, grid = resample(walls.image, walls.grid, cell)
    wall = share >= WALL_SHARE
    rooms = segment(without_wall_furniture(~wall, cell, params), cell, params)
    labels = rooms.labels
    edge = on_edge(labels, len(rooms) + 1)
    edge[0] = True
    keep = np.flatnonzero(~edge[1:])
    number = np.zeros(len(rooms) + 1, np.int32)
    number[keep + 1] = np.arange(1, len(keep) + 1)
    return rooms, number, grid, wall


def bounding(wall: np.ndarray, labels: np.ndarray) -> float:
    """The share of the wall cells next to a room cell (labels > 0; 8-neighbours), [0, 1]."""
    room = np.pad(labels > 0, 1)
    near = np.zeros(wall.shape, dtype=bool)
    rows, cols = wall.shape
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            near |= room[dr:dr + rows, dc:dc + cols]
    return float(np.count_nonzero(wall & near)) / max(int(np.count_nonzero(wall)), 1)


def detect(walls: WallImage, params: Params) -> Features:
    """The rooms of the walls as features: centroids (metres, the walls' frame), area (m^2)
    as strength, every room strong, their cells as labels, the doors between them (ordered
    as the features) and the share of the walls that bound them."""
    rooms, inside, grid, wall = inside_rooms(walls, params)
    labels = inside[rooms.labels]
    count = int(labels.max(initial=0))
    if count == 0:  # no room: its cells (none) are still there to say so
        return replace(empty_features(), labels=labels.astype(np.int32),
                       doors=np.zeros((0, 5)), bounding=0.0)
    cells = np.bincount(labels.ravel(), minlength=count + 1)[1:]
    rows, cols = np.indices(labels.shape)
    centre = np.column_stack([
        np.bincount(labels.ravel(), weights=cols.ravel(), minlength=count + 1)[1:],
        np.bincount(labels.ravel(), weights=rows.ravel(), minlength=count + 1)[1:],
    ]) / cells[:, None]
    xy = grid.pixels_to_xy(centre)
    area = cells * grid.resolution ** 2
    order = np.lexsort((area, xy[:, 1], xy[:, 0]))  # the canonical order of every detector
    number = np.zeros(count + 1, np.int32)
    number[order + 1] = np.arange(1, count + 1)
    # doors between two rooms inside: their rooms as feature indices, smaller first
    ends = number[inside[rooms.doors + 1]] - 1
    inner = (ends >= 0).all(axis=1)
    ends = np.sort(ends[inner], axis=1)
    at = grid.pixels_to_xy(rooms.door_cell[inner][:, ::-1].astype(np.float64))
    doors = np.column_stack([ends, at, rooms.door_width_m[inner]]).reshape(-1, 5)
    doors = doors[np.lexsort((doors[:, 1], doors[:, 0]))]
    return Features(xy=xy[order], strength=area[order], strong=np.ones(count, dtype=bool),
                    labels=number[labels], doors=doors, bounding=bounding(wall, labels))


def label_cell(features: Features) -> float:
    """The cell size of the rooms' labels (metres; their grid shares the input grid's origin
    and yaw), from a room's area and its cells; 0 without rooms."""
    if features.labels is None or not len(features):
        return 0.0
    cells = np.bincount(features.labels.ravel(), minlength=len(features) + 1)[1:]
    k = int(np.argmax(cells))
    return float(np.sqrt(features.strength[k] / cells[k])) if cells[k] else 0.0


def share_inside(features: Features, area: np.ndarray, grid: MetricGrid) -> np.ndarray:
    """(K,) the share of each room's cells whose centre lies in a cell where ``area`` (bool on
    ``grid``) is true."""
    cell = label_cell(features)
    if not cell:
        return np.zeros(len(features))
    rows, cols = np.nonzero(features.labels)
    lab_rows = features.labels.shape[0]
    # a label cell's centre in the input grid's pixels (both grids share the lower-left corner)
    u = (cols + 0.5) * cell / grid.resolution - 0.5
    v = grid.shape[0] - (lab_rows - rows - 0.5) * cell / grid.resolution - 0.5
    u, v = np.floor(u + 0.5).astype(np.int64), np.floor(v + 0.5).astype(np.int64)
    ok = (u >= 0) & (u < grid.shape[1]) & (v >= 0) & (v < grid.shape[0])
    hit = np.zeros(len(u), dtype=bool)
    hit[ok] = area[v[ok], u[ok]]
    room = features.labels[rows, cols] - 1
    total = np.bincount(room, minlength=len(features))
    return np.bincount(room, weights=hit, minlength=len(features)) / np.maximum(total, 1)


def drawn(truth: Features, map_: Features, most: float = 0.5,
          piece: float = PIECE) -> np.ndarray:
    """(T,) bool: the truth rooms over which the map drew a room: one lying for at least
    ``most`` of its cells within the truth room and holding at least ``piece`` of it (a piece
    of it), or one that holds ``most`` of it and of another truth room (a merger; see
    :func:`room_overlap`)."""
    found = np.zeros(len(truth), dtype=bool)
    if truth.labels is None or map_.labels is None or truth.labels.shape != map_.labels.shape:
        return found
    o = room_overlap(truth.labels, map_.labels, most, piece)
    found[:o.part.shape[0]] = o.part.any(axis=1) | o.merged
    return found


def overlap(truth: np.ndarray, map_: np.ndarray) -> np.ndarray:
    """(T, M) cells shared by each truth room and each map room: two int label rasters of one
    shape, 0 no room, room k at k + 1."""
    t, m = int(truth.max(initial=0)), int(map_.max(initial=0))
    both = (truth > 0) & (map_ > 0)
    pairs = (truth[both].astype(np.int64) - 1) * m + (map_[both] - 1)
    return np.bincount(pairs, minlength=t * m).reshape(t, m)


class RoomOverlap(NamedTuple):
    """How the rooms of two label rasters overlap (T truth rooms, M map rooms).

    shared: (T, M) cells each pair shares. iou: (T, M) their IoU. usable: (T, M) the IoU of
    the pairs that may match, 0 for the others: a truth room merged (a map room holds most of
    it and of another truth room, each a piece of the map room) or split (two or more map
    rooms lie mostly within it, each holding a piece of it), and the map rooms that merge or
    are its pieces. merged, split: (T,) those truth rooms; merging, pieces: (M,) those map
    rooms. part: (T, M) whether the map room is a piece of the truth room (lies mostly within
    it and holds a piece of it), split or not."""

    shared: np.ndarray
    iou: np.ndarray
    usable: np.ndarray
    merged: np.ndarray
    split: np.ndarray
    merging: np.ndarray
    pieces: np.ndarray
    part: np.ndarray


def room_overlap(truth: np.ndarray, map_: np.ndarray, most: float = 0.5,
                 piece: float = PIECE) -> RoomOverlap:
    """The overlap of the rooms of two label rasters of one shape (0 no room, room k at
    k + 1); ``most``: the share of a room that counts as most of it; ``piece``: the least share
    of a truth room a map room holds to be one of its pieces."""
    shared = overlap(truth, map_)
    t_cells = np.bincount(truth.ravel(), minlength=shared.shape[0] + 1)[1:]
    m_cells = np.bincount(map_.ravel(), minlength=shared.shape[1] + 1)[1:]
    union = t_cells[:, None] + m_cells[None, :] - shared
    iou = np.divide(shared, union, out=np.zeros(shared.shape), where=union > 0)
    of_truth = shared / np.maximum(t_cells, 1)[:, None]  # share of each truth room
    of_map = shared / np.maximum(m_cells, 1)[None, :]  # share of each map room
    # the map room holds most of the truth room, and the truth room is a piece of it
    holds = (of_truth >= most) & (of_map >= piece)
    merging = holds.sum(axis=0) >= 2  # holds two or more truth rooms
    merged = holds[:, merging].any(axis=1)
    # the map room lies mostly in the truth room and holds a piece of it
    part = (of_map >= most) & (of_truth >= piece)
    split = (part.sum(axis=1) >= 2) & ~merged
    pieces = part[split].any(axis=0) & ~merging
    # a merger, a split room and its pieces are what they are, not a match to one of them
    usable = np.where(merged[:, None] | split[:, None] | merging[None, :] | pieces[None, :],
                      0.0, iou)
    return RoomOverlap(shared, iou, usable, merged, split, merging, pieces, part)


def candidates(truth: Features, map_: Features, threshold: float,
               params: Params) -> Candidates:
    """Pairs of a truth room and a map room whose IoU is at least ``params.min_iou``, neither
    merged nor split (:func:`room_overlap`); cost 0 at an IoU of 1 and 1 at ``min_iou``;
    displacement: from the truth room's centroid to the map room's, metres. ``threshold``
    (metres) does not apply to rooms."""
    none = (np.zeros(0, int), np.zeros(0, int), np.zeros(0), np.zeros((0, 2)))
    if truth.labels is None or map_.labels is None or truth.labels.shape != map_.labels.shape \
            or not len(truth) or not len(map_):
        return none
    usable = room_overlap(truth.labels, map_.labels).usable
    i, j = np.nonzero(usable >= params.min_iou)
    cost = np.clip((1.0 - usable[i, j]) / max(1.0 - params.min_iou, 1e-9), 0.0, 1.0)
    return i, j, cost, map_.xy[j] - truth.xy[i]


#: A truth of one room (an outdoor place, a single hall) has no rooms to tell apart: its rooms'
#: scores are undefined, not 0 or 1.
MIN_ROOMS = 2
#: A truth whose rooms are next to less than this share of its walls has no closed rooms: what
#: its walls close off are pockets (parked cars, a corner of a building seen from the street,
#: a map whose doors all stand open), and its rooms' scores are undefined. The walls of a
#: building's plan bound its rooms for about half their cells or more; a street's, an eighth.
MIN_BOUNDING = 0.25


def no_closed_rooms(truth: Features) -> str | None:
    """Why a truth's rooms leave nothing to find (:data:`MIN_BOUNDING`), or None."""
    if truth.bounding is None or truth.bounding >= MIN_BOUNDING:
        return None
    return (f"the truth has no closed rooms: {100 * truth.bounding:.0f} % of its walls bound "
            f"one, fewer than {100 * MIN_BOUNDING:.0f} %: nothing to find")


DETECTOR = Detector("rooms", detect, candidates, Params, min_truth=MIN_ROOMS, noun="room",
                    nothing_to_find=no_closed_rooms)
