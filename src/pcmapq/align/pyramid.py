"""Multi-resolution global search: the yaw sweep of :func:`~pcmapq.align.coarse.coarse_search`
on a coarse raster, then a descent through rasters of half the cell each, down to ``finest``.

A large map cannot be searched at a fine cell in one sweep (a 400 m campus at 1 m cells is
2500 yaws of a 560 x 560 template), and at the coarse cell one sweep affords (the map's radius /
40) a building's rooms vanish, so a map of repeated structure lands on a wrong copy or a wrong
turn. The descent keeps the sweep's ``beam`` best distinct poses and, level by level, searches
the region each one stands for at the finer cell, as Olson's multi-resolution correlative
matching and Cartographer's fast correlative scan matcher do:

- a pose at level k stands for yaws within one level-k step (cell / radius radians: its
  farthest point moves by one cell) and positions within two cells: its children are 3 yaws x
  5 x 5 positions on the level's likelihood field (:func:`~pcmapq.align.coarse.likelihood_field`,
  sigma = the level's cell); each scores the mean field under the map's points;
- a region's score cannot exceed the mean, under the map's points at the parent pose, of the
  field max-pooled over the distance any point can move within the region (4 cells in each
  axis: one for the turn, two for the shift, one for rounding). Parents are taken in order of
  that bound, and once a bound falls to the ``beam``-th best score already found, the rest are
  pruned (branch and bound);
- each region's best child goes on; the ``PARENTS x beam`` best distinct ones are the next
  level's parents.

Points are the map's voxel centroids at half the level's cell, thinned evenly to at most
``max_points`` (the score is a mean: 8 000 points estimate it to about 1 %).
"""

from __future__ import annotations

import cv2
import numpy as np

from pcmapq.align.coarse import Candidate, Search, _pose, _suppress, likelihood_field
from pcmapq.core.grid import MetricGrid
from pcmapq.core.voxels import evenly, voxel_centroids

#: Distinct poses searched per level, in beams: the bound prunes all but a few of them.
PARENTS = 4
#: Children of a parent: yaws at -1, 0, +1 level steps; positions within SHIFT cells.
SHIFT = 2
#: Max-pooling half-width of the bound, cells: a turn of one step moves a point one cell, the
#: shift SHIFT cells, the rounding of points to cells one more.
BOUND = 1 + SHIFT + 1
#: Zero cells around the field that children read: a point clipped into this border reads only
#: zeros at every shift, as a point outside the field does.
WIDE = 2 * SHIFT + 1


class _Level:
    """One level of the descent: the likelihood field at ``cell`` metres (padded by one zero
    cell; and by WIDE, for the children's shifted reads), its max-pooled bound, and the map's
    points (N, 2, metres, about its centroid)."""

    def __init__(self, centred: np.ndarray, truth_xy: np.ndarray, cell: float, margin: float,
                 max_points: int) -> None:
        self.cell = cell
        self.grid = MetricGrid.covering(truth_xy, cell, margin=margin)
        field = likelihood_field(truth_xy, self.grid, cell)
        self.field = cv2.copyMakeBorder(field, 1, 1, 1, 1, cv2.BORDER_CONSTANT, value=0.0)
        self.wide = cv2.copyMakeBorder(field, WIDE, WIDE, WIDE, WIDE, cv2.BORDER_CONSTANT,
                                       value=0.0)
        size = 2 * BOUND + 1
        self.bound = cv2.dilate(self.field, np.ones((size, size), np.uint8))
        self.points = evenly(voxel_centroids(centred, 0.5 * cell), max_points)

    def pixels(self, yaws: np.ndarray, xy: np.ndarray) -> np.ndarray:
        """Padded-field pixels (len(yaws), N, 2) int64 of the points turned by each yaw
        (radians) about the centroid, the centroid at ``xy`` (truth frame, metres)."""
        c, s = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
        x, y = self.points[:, 0], self.points[:, 1]
        world = np.stack([c * x - s * y + xy[0], s * x + c * y + xy[1]], axis=-1)
        uv = self.grid.xy_to_pixels(world.reshape(-1, 2)).reshape(world.shape)
        return np.floor(uv + 1.5).astype(np.int64)  # + 1: the padding

    def mean(self, image: np.ndarray, uv: np.ndarray) -> np.ndarray:
        """Mean of ``image`` (padded) under pixels (..., N, 2); outside reads the zero border."""
        rows, cols = image.shape
        u = np.clip(uv[..., 0], 0, cols - 1)
        v = np.clip(uv[..., 1], 0, rows - 1)
        return image[v, u].mean(axis=-1)

    def children(self, yaw: float, xy: np.ndarray, step: float) -> np.ndarray:
        """The best child of the region of (yaw, xy): one row (score, yaw, x, y). Each child's
        score is :meth:`mean` of the padded field under its shifted pixels, read in the wide
        field at flat indices: a pixel outside reads 0 either way."""
        yaws = yaw + step * np.arange(-1, 2)
        uv = self.pixels(yaws, xy)  # (3, N, 2), in the field padded by one cell
        rows, cols = self.wide.shape
        u = np.clip(uv[..., 0] + (WIDE - 1), SHIFT, cols - 1 - SHIFT)
        v = np.clip(uv[..., 1] + (WIDE - 1), SHIFT, rows - 1 - SHIFT)
        d = np.arange(-SHIFT, SHIFT + 1)
        du, dv = (a.ravel() for a in np.meshgrid(d, d))
        flat = (v * cols + u)[:, None, :] + (dv * cols + du)[None, :, None]  # (3, 25, N)
        scores = self.wide.ravel()[flat].mean(axis=-1)  # (3, 25)
        i, j = np.unravel_index(int(np.argmax(scores)), scores.shape)
        best = xy + self.cell * np.array([du[j], -dv[j]])
        return np.array([scores[i, j], yaws[i], best[0], best[1]])


def descend(search: Search, map_xy: np.ndarray, truth_xy: np.ndarray, *, finest: float,
            beam: int, top_k: int, max_points: int = 8_000) -> Search:
    """Refine a rigid sweep's poses (``search``, of :func:`~pcmapq.align.coarse.coarse_search`)
    level by level, halving its cell until it is at most ``finest`` metres.

    map_xy, truth_xy: (N, 2) metres, each in its own frame (the sweep's inputs). beam: poses
    kept per level; top_k: candidates returned. Returns the search at the finest level: its
    candidates best first, its poses the best child of every region searched, its cell and
    yaw step that level's.
    """
    centred = map_xy - search.centre
    rows = search.poses[:, :4]
    cell, step = search.cell, search.yaw_step
    while cell > finest * (1 + 1e-9):
        cell, step = 0.5 * cell, 0.5 * step
        parents = _suppress(rows, PARENTS * beam, 3 * step, 4 * cell)
        level = _Level(centred, truth_xy, cell, search.radius + 4 * cell, max_points)
        rows = _level_rows(level, parents, step, beam)
    rows = rows[np.argsort(-rows[:, 0], kind="stable")]
    best = _suppress(rows, top_k, 3 * step, 4 * cell)
    candidates = [Candidate(_pose(yaw, xy, search.centre), float(score))
                  for score, yaw, *xy in best]
    return Search(candidates, rows, search.centre, search.radius, cell, step)


def _level_rows(level: _Level, parents: np.ndarray, step: float, beam: int) -> np.ndarray:
    """The best child (score, yaw, x, y) of every parent region not pruned by its bound."""
    bounds = np.array([level.mean(level.bound, level.pixels(np.array([yaw]), xy))[0]
                       for _, yaw, *xy in parents])
    order = np.argsort(-bounds, kind="stable")
    found: list[np.ndarray] = []
    for i in order:
        scores = sorted((r[0] for r in found), reverse=True)
        if len(scores) >= beam and bounds[i] <= scores[beam - 1]:
            break  # no region left can beat the beam's worst
        found.append(level.children(parents[i, 1], parents[i, 2:4], step))
    return np.array(found)
