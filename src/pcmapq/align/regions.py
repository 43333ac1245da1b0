"""Where a map breaks: each region of the map, already placed by the global alignment, aligned
again on its own to the truth (point-to-line ICP of the region's walls from where the global
pose put them). A consistent map needs no region to move; a map that drifted, bent or broke
apart needs its regions moved by offsets that grow where it breaks.

Regions are square tiles of the truth frame; each tile is aligned with the map points of a
window around it, the tile grown by a quarter of its side on every side (walls of
neighbouring tiles hold a corridor in place along its length), and reported at the centroid
of its own points. Frames: every position, offset and turn is in the truth frame, metres
and degrees; ``offset`` takes the region's points from where the global pose put them to
where they fit the truth."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.align.point_to_line import LineTarget, refine_point_to_line
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxel_table import streamed_centroids

#: Map points are taken at this voxel, metres, before they are cut into regions.
VOXEL = 0.15
#: Regions at most this many tiles across the map's larger side (larger maps get larger tiles).
MAX_TILES = 24
#: A tile holding fewer points than this (at VOXEL: metres of wall / VOXEL) is no region.
MIN_POINTS = 20
#: A region is aligned with the map points of its tile grown by this share of a side on each
#: side (walls of the neighbouring tiles hold a corridor along its length).
MARGIN = 0.25
#: ICP stages of a region: pairs within these distances, metres (wide first, then fine).
STAGES = (1.0, 0.4)
#: A fit from a part's pose replaces the fit from the map's pose when it puts this much more of
#: the region's points on truth walls.
BETTER = 0.1
#: A region's ICP stops once a step moves it less than this, metres (a tenth of a millimetre:
#: offsets are reported to the centimetre).
SETTLED = 1e-4
#: A region is held in place in both directions when its matched walls' normals spread so that
#: the weaker direction has at least this share of the stronger one (a lone corridor does not),
#: and at least MIN_FIT of its window's points lie on truth walls once it is aligned.
MIN_SPREAD = 0.1
MIN_FIT = 0.5


@dataclass(frozen=True)
class Consistency:
    """The regions of one placed map, as arrays (K regions).

    tile_m: a tile's side, metres. centre: (K, 2) centroid of each region's map points, truth
    frame, metres. offset: (K, 2) the move that fits the region to the truth, metres. turn_deg:
    (K,) its turn, degrees. points: (K,) the region's map points (at VOXEL). fit_before,
    fit_after: (K,) share of its points within ``tolerance_m`` of a truth wall at the global
    pose and after the region's own alignment. held: (K,) whether the region, aligned,
    lies on truth walls that hold it in both directions (its offset is then sure; otherwise it
    may slide along its walls, or fit none)."""

    tile_m: float
    tolerance_m: float
    centre: np.ndarray
    offset: np.ndarray
    turn_deg: np.ndarray
    points: np.ndarray
    fit_before: np.ndarray
    fit_after: np.ndarray
    held: np.ndarray

    @classmethod
    def empty(cls, tile_m: float, tolerance_m: float) -> Consistency:
        """A consistency map with no region."""
        none = np.zeros((0, 2))
        return cls(tile_m, tolerance_m, none, none, np.zeros(0), np.zeros(0, int), np.zeros(0),
                   np.zeros(0), np.zeros(0, bool))

    @property
    def offset_m(self) -> np.ndarray:
        """(K,) length of each region's offset, metres."""
        return np.hypot(self.offset[:, 0], self.offset[:, 1])

    def largest(self) -> int | None:
        """Index of the held region with the largest offset; None without one."""
        held = np.flatnonzero(self.held)
        return None if len(held) == 0 else int(held[np.argmax(self.offset_m[held])])

    def local_fitness(self) -> float:
        """Share of the regions' points within the tolerance of a truth wall once each region
        is aligned on its own, [0, 1]."""
        total = self.points.sum()
        return float((self.fit_after * self.points).sum() / total) if total else 0.0

    def global_fitness(self) -> float:
        """Share of the regions' points within the tolerance of a truth wall at the global
        pose, [0, 1]."""
        total = self.points.sum()
        return float((self.fit_before * self.points).sum() / total) if total else 0.0


def _fitness(points: np.ndarray, target: LineTarget, tolerance: float) -> float:
    return float((target.nearest(points, tolerance) >= 0).mean())


def _held(points: np.ndarray, target: LineTarget, tolerance: float) -> bool:
    """Whether ``points`` (N, 2, truth frame) lie on truth walls (at least MIN_FIT of them
    within ``tolerance``) that face two ways enough to hold a translation: the smaller
    eigenvalue of the sum of their normals' outer products is at least MIN_SPREAD of the
    larger."""
    j = target.nearest(points, tolerance)
    ok = j >= 0
    if ok.sum() < max(3, MIN_FIT * len(points)):
        return False
    n = target.normals(j[ok])
    low, high = np.linalg.eigvalsh(n.T @ n)
    return bool(low >= MIN_SPREAD * high)


def _fit(window: np.ndarray, own: np.ndarray, target: LineTarget, start: Similarity2D,
         tolerance: float) -> tuple[Similarity2D, float] | None:
    """The window's points (truth frame) aligned from ``start`` (a move in the truth frame):
    the move and the share of the region's ``own`` points it puts on truth walls; None when
    the window slid more than twice the widest pairing distance away from ``start``."""
    local = start
    for distance in STAGES:
        local = refine_point_to_line(window, target, local, distance, iterations=15,
                                     settled=SETTLED)
    centre = own.mean(axis=0, keepdims=True)
    if np.hypot(*(local.apply(centre) - start.apply(centre))[0]) > 2 * STAGES[0]:
        return None
    return local, _fitness(local.apply(own), target, tolerance)


def _tile_codes(tiles: np.ndarray) -> tuple[np.ndarray, int]:
    """One increasing integer per tile (``tiles``: (T, 2) keys, sorted as ``np.unique`` sorts
    rows) and the stride of its first key, chosen so that a neighbour's code is the tile's plus
    one less or more, or ``height`` less or more, and so on."""
    low = tiles.min(axis=0) - 1
    height = int(tiles[:, 1].max() - low[1]) + 2
    return (tiles[:, 0] - low[0]) * height + (tiles[:, 1] - low[1]), height


def _tile_points(k: int, code: np.ndarray, height: int, order: np.ndarray,
                 bounds_at: np.ndarray) -> np.ndarray:
    """Indices, increasing, of the points of tile ``k`` and of its 8 neighbours: ``order``
    lists the points tile by tile, tile ``j``'s from ``bounds_at[j]`` to ``bounds_at[j + 1]``."""
    wanted = code[k] + (np.arange(-1, 2)[:, None] * height + np.arange(-1, 2)).ravel()
    near = np.searchsorted(code, wanted)
    near = near[(near < len(code)) & (code[np.minimum(near, len(code) - 1)] == wanted)]
    return np.sort(np.concatenate([order[bounds_at[j]:bounds_at[j + 1]] for j in near]))


def regions(map_xy: np.ndarray, transform: Similarity2D, target: LineTarget,
            tolerance: float = 0.2, tile_m: float = 4.0,
            starts: tuple[tuple[Similarity2D, tuple[float, float]], ...] = ()
            ) -> Consistency:
    """The regions of the map (N, 2, map frame) placed by ``transform`` (map -> truth), each
    aligned on its own to the truth walls of ``target`` (truth frame, metres).

    tile_m: a tile's side, metres (grown so that the map spans at most MAX_TILES tiles).
    tolerance: the distance, metres, within which a point lies on a truth wall.
    starts: other map -> truth poses, each with where it applies (truth frame, metres): the
    poses of the map's parts placed on their own and their centroids as the map's pose puts
    them (see :mod:`pcmapq.align.parts`). Each region is also aligned from the pose whose place
    is nearest, and that fit replaces the one from the map's own pose when it puts BETTER more
    of the region's points on truth walls: a part that broke off further than ICP reaches from
    the map's pose is fitted from its own."""
    # moved and grouped a chunk of points at a time: a large map is never copied whole
    placed = streamed_centroids(map_xy, VOXEL, move=transform.apply)
    if len(placed) == 0 or len(target.points) < 3:
        return Consistency.empty(tile_m, tolerance)
    span = float(np.ptp(placed, axis=0).max())
    tile = max(tile_m, span / MAX_TILES)
    keys = np.floor(placed / tile).astype(np.int64)
    tiles, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    bounds_at = np.concatenate([[0], np.cumsum(counts)])
    code, height = _tile_codes(tiles)
    # each start as a move of the placed points, truth frame: start o transform^-1
    moves = [pose.compose(transform.inverse()) for pose, _ in starts]
    places = np.array([where for _, where in starts], dtype=np.float64).reshape(-1, 2)
    rows = []
    for k in np.flatnonzero(counts >= MIN_POINTS):
        own = placed[order[bounds_at[k]:bounds_at[k + 1]]]
        lo, hi = (tiles[k] - MARGIN) * tile, (tiles[k] + 1 + MARGIN) * tile
        # the window lies within the tile and its 8 neighbours (MARGIN < 1): only their
        # points are compared, in the map's order, so the window is placed[inside] exactly
        nearby = placed[_tile_points(k, code, height, order, bounds_at)]
        window = nearby[np.all((nearby >= lo) & (nearby < hi), axis=1)]
        before = _fitness(own, target, tolerance)
        local, after = Similarity2D(), before  # slid out of reach from every start: not moved
        found = False
        nearest = np.argmin(np.hypot(*(places - own.mean(axis=0)).T)) if len(moves) else None
        tries = [Similarity2D()] + ([] if nearest is None else [moves[nearest]])
        for move in tries:  # the map's own pose first: another start must fit clearly better
            fitted = _fit(window, own, target, move, tolerance)
            if fitted is not None and (not found or fitted[1] > after + BETTER):
                (local, after), found = fitted, True
        centre = own.mean(axis=0)
        shift = local.apply(centre[None])[0] - centre
        rows.append((*centre, *shift, np.degrees(local.yaw), len(own), before, after,
                     _held(local.apply(window), target, tolerance)))
    if not rows:
        return Consistency.empty(tile, tolerance)
    # to the micrometre (and 1e-6 of a share or degree), as results are saved: the figures
    # made from them are then the same read back from JSON
    table = np.round(np.array(rows, dtype=np.float64), 6) + 0.0
    return Consistency(tile, tolerance, table[:, :2], table[:, 2:4], table[:, 4],
                       table[:, 5].astype(int), table[:, 6], table[:, 7], table[:, 8] > 0)
