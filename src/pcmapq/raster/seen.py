"""The area a run's scans saw, filled once in the map's own frame (the ``seen`` footprint).

Each scan's view (:func:`pcmapq.raster.footprint.view_outlines`) is filled into a lattice of
:data:`~pcmapq.io.clouds.SEEN_CELL` squares in the map's frame
(:class:`~pcmapq.io.clouds.SeenCells`) as the scan is taken, so a map grown scan by scan
fills each view once; the lattice is then drawn into the truth's grid under the map's
alignment, one warp per evaluation. Vertices are placed on the lattice in whole 1/256 cells,
so a view fills the same cells whatever part of the lattice is held.
"""

from __future__ import annotations

import cv2
import numpy as np

from pcmapq.core.bounds import bounds
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, LaserScans, endpoint_scans, endpoints
from pcmapq.io.clouds import SEEN_CELL, SeenCells
from pcmapq.raster.footprint import joined_readings, view_outlines

#: Fractional bits of the vertices given to OpenCV's polygon filling.
SHIFT = 8
#: Nothing seen yet.
NO_VIEW = SeenCells(np.zeros((0, 0), bool), (0, 0))


def add_views(seen: SeenCells, views: np.ndarray) -> SeenCells:
    """``seen`` with the views (K, V, 2; metres, map frame; star-shaped polygons) filled in,
    the lattice grown to hold them. The cells ``seen`` holds are not changed."""
    views = np.asarray(views, dtype=np.float64).reshape(-1, np.shape(views)[-2], 2)
    if views.size == 0:
        return seen
    fixed = np.round(views * ((1 << SHIFT) / SEEN_CELL)).astype(np.int64) - (1 << (SHIFT - 1))
    low, high = bounds(fixed.reshape(-1, 2))
    low, high = low >> SHIFT, (high >> SHIFT) + 1
    if seen.cells.size:
        low = np.minimum(low, seen.corner)
        high = np.maximum(high, np.add(seen.corner, seen.cells.shape[::-1]) - 1)
    cells = np.zeros((int(high[1] - low[1]) + 1, int(high[0] - low[0]) + 1), np.uint8)
    if seen.cells.size:
        x, y = np.subtract(seen.corner, low)
        rows, cols = seen.cells.shape
        cells[y:y + rows, x:x + cols] = seen.cells
    shifted = (fixed - (low << SHIFT)).astype(np.int32)
    for polygon in shifted:  # one at a time: filled together, overlaps would cancel
        cv2.fillPoly(cells, [polygon], 1, lineType=cv2.LINE_8, shift=SHIFT)
    return SeenCells(cells.view(bool), (int(low[0]), int(low[1])))


def seen_on(seen: SeenCells, transform: Similarity2D, grid: MetricGrid) -> np.ndarray:
    """The cells of ``grid`` (truth frame, bool) whose centres the map's ``transform``
    (``p_truth = transform(p_map)``) puts on a seen lattice cell: the nearest one."""
    if seen.cells.size == 0:
        return np.zeros(grid.shape, bool)
    to_lattice = np.array([[1 / SEEN_CELL, 0.0, -0.5 - seen.corner[0]],
                           [0.0, 1 / SEEN_CELL, -0.5 - seen.corner[1]], [0.0, 0.0, 1.0]])
    m = to_lattice @ transform.inverse().matrix @ grid.pixel_to_xy_matrix()
    rows, cols = grid.shape
    drawn = cv2.warpAffine(seen.cells.view(np.uint8), m[:2], (cols, rows),
                           flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP,
                           borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return drawn.view(bool)


def scan_views(origins: np.ndarray, xy: np.ndarray, scan: np.ndarray, gap: float) -> np.ndarray:
    """The views of K scans (K, V, 2; metres, map frame; :func:`view_outlines`) from their
    scanners at ``origins`` (K, 2), drawn by the readings ``xy`` (N, 2; ``scan`` (N,) the scan
    of each, in beam order) that draw a wall as a line, their neighbours within ``gap`` metres
    (:func:`joined_readings`): a lone reading far away does not stretch a view."""
    joined = joined_readings(xy, scan, gap)
    return view_outlines(origins, xy[joined], scan[joined])


def seen_of_scans(scans: LaserScans, gap: float,
                  max_range: float = DEFAULT_MAX_RANGE) -> SeenCells:
    """The area a CARMEN log's scans saw at their logged poses (readings up to ``max_range``
    metres; ``gap``: see :func:`scan_views`), in the log's world frame."""
    xy = endpoints(scans.poses, scans.ranges, scans.angles, max_range)
    scan = endpoint_scans(scans.poses, scans.ranges, scans.angles, max_range)
    return add_views(NO_VIEW, scan_views(scans.poses[:, :2], xy, scan, gap))
