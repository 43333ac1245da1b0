"""Rooms and doors of a map's free space: a distance-transform watershed whose basins are
merged wherever the passage between them is nearly as wide as the smaller of the two.

Every free cell's Euclidean distance to the nearest non-free cell is its clearance; a room is a
region of high clearance, a door a narrow passage between two such regions:

1. furniture is taken out first: non-free pieces (8-connected) that lie wholly within free
   space (they touch no other obstacle and not the raster's edge) and fit in a square of
   ``furniture_m`` are made free, so that chairs and bins do not split their room (a piece of
   wall between two doors is longer than that);
2. the clearance's peaks (h-maxima of ``peak_h_m``: a plateau or a ridge that does not rise by
   that much above its surroundings is one peak) seed a watershed of the free cells;
3. neighbouring basins are merged, widest passage first (union-find, as Kruskal's algorithm),
   when the passage's clearance is at least ``door_ratio`` of the smaller basin's peak: a
   corridor cut by its own bumps becomes one room again, a room stays apart from its
   neighbour behind a door;
4. a room smaller than ``min_room_m2`` joins the neighbour it has the widest passage to; one
   with no neighbour (a space walled in on its own: between clutter, inside a pillar) is no
   room when it is smaller than ``min_space_m2``.

The rooms' graph: a door between two rooms is the widest passage left between them, reported
by its position and width (twice the clearance there). Every length is in metres; positions
are cells (row, column) of the raster, which :class:`~pcmapq.core.grid.MetricGrid` takes to
metres.

Anchors: the distance-transform segmentation of Bormann et al. ("Room Segmentation: Survey,
Implementation, and Analysis", ICRA 2016), with the merge rule of MAORIS (Mielle et al., 2018)
that compares a passage with the rooms it joins instead of one global threshold.

The rooms detector (:mod:`pcmapq.features.rooms`) finds them on the walls every detector sees.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from pcmapq.core.bounds import on_edge
from pcmapq.core.morphology import precise_distance
from pcmapq.features.peaks import h_maxima

#: The door test's slack: clearances are float32 metres, so a passage of exactly ``door_ratio``
#: of a peak in whole cells (0.7 m of 1.0 m) would fall either side of it by rounding alone.
TIE = 1.0 - 1e-6


@dataclass(frozen=True)
class Params:
    """Room segmentation parameters, lengths in metres, areas in square metres.

    door_ratio: two basins stay apart when the clearance of the widest passage between them is
        below this share of the smaller basin's peak clearance.
    peak_h_m: a clearance peak must rise this much above its surroundings to seed a basin.
    min_room_m2: rooms smaller than this join their neighbour.
    min_space_m2: a space walled in on its own smaller than this is no room.
    furniture_m: obstacles wholly inside free space that fit in a square of this side are
        furniture.
    cell_m: as a detector, the cell size the rooms are found on (larger on a raster of more
        than :data:`MAX_CELLS` such cells).
    min_iou: as a detector, the least IoU of a truth room and a map room that may match.
    min_seen: as a detector, the least share of a truth room inside the map's footprint for
        it to count (a room the map saw only in part cannot be judged as a room).
    min_drawn: as a detector, the least share inside the footprint of a truth room over which
        the map drew a room (one lying mostly within it and holding a tenth of it, or one that
        holds most of it and of another truth room) for it to count: a room a bent map drew out
        of place, partly off the footprint, is judged; a room a partial map saw only in part is
        open to its unknown cells, draws no room, and counts at ``min_seen`` only.
    """

    door_ratio: float = 0.7
    peak_h_m: float = 0.2
    min_room_m2: float = 1.0
    min_space_m2: float = 0.5
    furniture_m: float = 1.0
    cell_m: float = 0.1
    min_iou: float = 0.5
    min_seen: float = 0.98
    min_drawn: float = 0.5


@dataclass(frozen=True)
class Rooms:
    """The rooms of one raster (K rooms, D doors).

    labels: (rows, cols) int32, 0 outside every room, room k at k + 1 (its free cells and
        its furniture).
    area_m2: (K,) area of each room. centroid: (K, 2) its centroid, cells (row, col).
    clearance_m: (K,) its largest clearance (the radius of the largest disc it holds).
    doors: (D, 2) the two rooms (indices 0..K-1, the smaller first) each door joins.
    door_cell: (D, 2) where the door's passage is narrowest, cells (row, col).
    door_width_m: (D,) the door's width, twice its clearance.
    """

    labels: np.ndarray
    area_m2: np.ndarray
    centroid: np.ndarray
    clearance_m: np.ndarray
    doors: np.ndarray
    door_cell: np.ndarray
    door_width_m: np.ndarray

    def __len__(self) -> int:
        return len(self.area_m2)


def without_furniture(free: np.ndarray, resolution: float, largest_m: float) -> np.ndarray:
    """``free`` (bool) with the obstacles that lie wholly within it and fit in a square of
    ``largest_m`` made free: 8-connected non-free pieces that do not reach the raster's edge."""
    blocked = np.pad(~free, 1, constant_values=True).view(np.uint8)
    _, label, stats, _ = cv2.connectedComponentsWithStats(blocked, connectivity=8)
    side = np.maximum(stats[:, cv2.CC_STAT_WIDTH], stats[:, cv2.CC_STAT_HEIGHT])
    small = side * resolution <= largest_m
    small[label[0, 0]] = False  # the piece around the edge
    small[0] = False  # free cells
    return free | small[label[1:-1, 1:-1]]


#: As a detector: a straight piece of wall at least this long (metres) is a wall, never
#: furniture against it.
WALL_LINE_M = 1.5
#: As a detector: an obstacle holding a square of this side (metres, and at least 3 cells) is
#: solid, not a wall (the walls every detector sees are a band 0.15 m wide).
SOLID_M = 0.4
#: Directions (degrees) of the straight pieces of wall.
LINE_ANGLES = tuple(range(0, 180, 15))


def _line(length: int, degrees: float) -> np.ndarray:
    """A straight line of ``length`` cells through the centre of a square kernel (uint8)."""
    half = (length - 1) / 2
    t = np.deg2rad(degrees)
    dx, dy = half * np.cos(t), -half * np.sin(t)
    side = 2 * int(np.ceil(max(abs(dx), abs(dy)))) + 1
    kernel = np.zeros((side, side), np.uint8)
    c = side // 2
    cv2.line(kernel, (round(c - dx), round(c - dy)), (round(c + dx), round(c + dy)), 1)
    return kernel


def without_wall_furniture(free: np.ndarray, resolution: float, params: Params) -> np.ndarray:
    """``free`` (bool, thin walls) with the furniture that stands against its walls made free.

    For walls drawn as thin lines (the band every detector sees): the obstacle cells that lie
    on no straight piece of wall :data:`WALL_LINE_M` long, in any of :data:`LINE_ANGLES`, are
    what hangs off the walls. A piece of them (8-connected) that fits in a square of
    ``furniture_m``, does not reach the raster's edge, and is solid (holds a square of
    :data:`SOLID_M`) or closes a pocket (a walled-in free space under ``min_space_m2``) with
    the wall, is furniture: it and its pockets are made free. The wall behind it stays, since
    it lies on a straight piece of wall; a short wall between two doors is no such piece but
    neither solid nor closing a pocket, so it stays too."""
    wall = np.ascontiguousarray(~free).view(np.uint8)
    length = max(int(round(WALL_LINE_M / resolution)), 3)
    lines = np.zeros(free.shape, dtype=bool)
    for degrees in LINE_ANGLES:
        lines |= cv2.morphologyEx(wall, cv2.MORPH_OPEN, _line(length, degrees)).view(bool)
    rest = wall.view(bool) & ~lines
    if not rest.any():
        return free
    padded = np.pad(free, 1, constant_values=True).view(np.uint8)
    _, label, stats, _ = cv2.connectedComponentsWithStats(padded, connectivity=4)
    small = stats[:, cv2.CC_STAT_AREA] * resolution ** 2 < params.min_space_m2
    small[label[0, 0]] = small[0] = False  # the free space around the edge; the walls
    pocket = small[label[1:-1, 1:-1]]
    count, piece, stats, _ = cv2.connectedComponentsWithStats(rest.view(np.uint8),
                                                               connectivity=8)
    side = np.maximum(stats[:, cv2.CC_STAT_WIDTH], stats[:, cv2.CC_STAT_HEIGHT]) * resolution
    by_pocket = np.zeros(count, dtype=bool)
    by_pocket[piece[cv2.dilate(pocket.view(np.uint8), np.ones((3, 3), np.uint8)).view(bool)]] \
        = True
    k = max(int(round(SOLID_M / resolution)), 3)  # on coarse cells a wall fills two
    solid = np.zeros(count, dtype=bool)
    solid[piece[cv2.morphologyEx(rest.view(np.uint8), cv2.MORPH_OPEN,
                                 np.ones((k, k), np.uint8)).view(bool)]] = True
    furniture = (side <= params.furniture_m) & (by_pocket | solid) & ~on_edge(piece, count)
    furniture[0] = False
    made_free = furniture[piece]
    # the pockets those pieces closed
    _, holes = cv2.connectedComponents(pocket.view(np.uint8), connectivity=4)
    grown = cv2.dilate(made_free.view(np.uint8), np.ones((3, 3), np.uint8)).view(bool)
    near = np.unique(holes[grown & pocket])
    return free | made_free | np.isin(holes, near[near > 0])


def _passages(basin: np.ndarray, clearance: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The widest passage between each pair of touching basins (4-neighbours): pairs (P, 2)
    of basin labels (the smaller first), the passage's clearance (P,) and its cell (P,) as a
    flat index (the cell of the pair with the smaller clearance)."""
    a_all, b_all, v_all, at_all = [], [], [], []
    flat_b, flat_c = basin.ravel(), clearance.ravel()
    cols = basin.shape[1]
    for first, second in (((slice(None), slice(None, -1)), (slice(None), slice(1, None))),
                          ((slice(None, -1), slice(None)), (slice(1, None), slice(None)))):
        la, lb = basin[first], basin[second]
        edge = (la != lb) & (la > 0) & (lb > 0)
        r, c = np.nonzero(edge)
        i = r * cols + c
        j = i + (1 if first[0] == slice(None) else cols)
        ca, cb = flat_c[i], flat_c[j]
        a_all.append(flat_b[i])
        b_all.append(flat_b[j])
        v_all.append(np.minimum(ca, cb))
        at_all.append(np.where(ca <= cb, i, j))
    a, b = np.concatenate(a_all), np.concatenate(b_all)
    value, at = np.concatenate(v_all), np.concatenate(at_all)
    low, high = np.minimum(a, b), np.maximum(a, b)
    # the widest passage of each pair: sort by pair, then by clearance, take each pair's last
    order = np.lexsort((at, value, high, low))
    low, high, value, at = low[order], high[order], value[order], at[order]
    last = np.ones(len(low), dtype=bool)
    last[:-1] = (low[1:] != low[:-1]) | (high[1:] != high[:-1])
    return np.column_stack([low[last], high[last]]), value[last], at[last]


def _root(parent: np.ndarray, k: int) -> int:
    while parent[k] != k:
        parent[k] = parent[parent[k]]
        k = parent[k]
    return k


def segment(free: np.ndarray, resolution: float, params: Params | None = None) -> Rooms:
    """The rooms of the free cells ``free`` (bool raster of ``resolution`` metres a cell); see
    the module docstring."""
    from skimage.segmentation import watershed  # loaded when rooms are segmented

    params = Params() if params is None else params
    free = without_furniture(np.asarray(free, dtype=bool), resolution, params.furniture_m)
    clearance = precise_distance(free.view(np.uint8)) * np.float32(resolution)
    peaks = h_maxima(clearance, params.peak_h_m) & free
    _, markers = cv2.connectedComponents(peaks.view(np.uint8), connectivity=8)
    basin = watershed(-clearance, markers, mask=free).astype(np.int32)
    count = int(basin.max())
    top = np.zeros(count + 1, np.float32)
    np.maximum.at(top, basin.ravel(), clearance.ravel())
    area = np.bincount(basin.ravel(), minlength=count + 1) * resolution ** 2

    pairs, value, at = _passages(basin, clearance)
    parent = np.arange(count + 1)
    peak, size = top.astype(np.float64), area.astype(np.float64)
    for k in np.lexsort((pairs[:, 1], pairs[:, 0], -value)):  # widest passage first
        ra, rb = _root(parent, pairs[k, 0]), _root(parent, pairs[k, 1])
        if ra != rb and value[k] >= params.door_ratio * min(peak[ra], peak[rb]) * TIE:
            parent[rb] = ra
            peak[ra], size[ra] = max(peak[ra], peak[rb]), size[ra] + size[rb]
    roots = np.array([_root(parent, k) for k in range(count + 1)])

    # small rooms join the neighbour they have the widest passage to, smallest first
    while True:
        pairs_r = roots[pairs]
        between = pairs_r[:, 0] != pairs_r[:, 1]
        small = [r for r in np.unique(roots[1:]) if size[r] < params.min_room_m2]
        joined = False
        for r in sorted(small, key=lambda r: (size[r], r)):
            touching = between & ((pairs_r[:, 0] == r) | (pairs_r[:, 1] == r))
            if not touching.any():
                continue
            k = np.flatnonzero(touching)[np.argmax(value[touching])]
            other = pairs_r[k, 1] if pairs_r[k, 0] == r else pairs_r[k, 0]
            roots[roots == r] = other
            size[other] += size[r]
            peak[other] = max(peak[other], peak[r])
            joined = True
            break
        if not joined:
            break

    kept = np.unique(roots[1:])
    kept = kept[size[kept] >= params.min_space_m2]  # a space walled in alone
    number = np.zeros(count + 1, np.int32)
    number[kept] = np.arange(1, len(kept) + 1)
    final = number[roots]
    final[0] = 0
    labels = final[basin]
    k_rooms = len(kept)
    cells = np.bincount(labels.ravel(), minlength=k_rooms + 1)[1:]
    rows, cols = np.indices(labels.shape)
    centroid = np.column_stack([
        np.bincount(labels.ravel(), weights=rows.ravel(), minlength=k_rooms + 1)[1:],
        np.bincount(labels.ravel(), weights=cols.ravel(), minlength=k_rooms + 1)[1:],
    ]) / np.maximum(cells, 1)[:, None]
    clear = np.zeros(k_rooms + 1, np.float32)  # the clearance's own type: no cast per cell
    np.maximum.at(clear, labels.ravel(), clearance.ravel())

    # doors: the widest passage left between two rooms
    room_pairs = final[pairs]
    apart = (room_pairs[:, 0] != room_pairs[:, 1]) & (room_pairs > 0).all(axis=1)
    ra = np.minimum(room_pairs[apart, 0], room_pairs[apart, 1])
    rb = np.maximum(room_pairs[apart, 0], room_pairs[apart, 1])
    v, where = value[apart], at[apart]
    order = np.lexsort((where, -v, rb, ra))
    ra, rb, v, where = ra[order], rb[order], v[order], where[order]
    first = np.ones(len(ra), dtype=bool)
    first[1:] = (ra[1:] != ra[:-1]) | (rb[1:] != rb[:-1])
    door_cell = np.column_stack(np.unravel_index(where[first], labels.shape))
    return Rooms(labels, cells * resolution ** 2, centroid, clear[1:].astype(np.float64),
                 np.column_stack([ra[first], rb[first]]) - 1, door_cell, 2.0 * v[first])
