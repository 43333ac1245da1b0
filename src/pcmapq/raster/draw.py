"""Drawing maps into a MetricGrid: points as hit counts, convex polygons as cells, occupancy
images by warping."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import cv2
import numpy as np

from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.grid import MetricGrid

if TYPE_CHECKING:
    from pcmapq.core.transform import Similarity2D

#: Points counted at once by :func:`hit_counts` (its temporaries: about 40 bytes a point).
CHUNK = 1 << 22


def hit_counts(xy: np.ndarray, grid: MetricGrid,
               move: Callable[[np.ndarray], np.ndarray] | None = None) -> np.ndarray:
    """Number of points (N, 2, metres, grid frame) in each cell: (rows, cols) int32. ``move``:
    applied to the points first (e.g. map frame -> grid frame), a chunk at a time, so that a
    large cloud is never copied whole."""
    rows, cols = grid.shape
    counts = np.zeros(rows * cols, dtype=np.int64)
    for start in range(0, len(xy), CHUNK):
        part = xy[start:start + CHUNK]
        uv = np.floor(grid.xy_to_pixels(part if move is None else move(part)) + 0.5)
        uv = uv.astype(np.int64)
        inside = (uv[:, 0] >= 0) & (uv[:, 0] < cols) & (uv[:, 1] >= 0) & (uv[:, 1] < rows)
        flat = uv[inside, 1] * cols + uv[inside, 0]
        if len(flat):  # a chunk's points lie close together: count over their range only
            low = int(flat.min())
            hits = np.bincount(flat - low)
            counts[low:low + len(hits)] += hits
    return counts.reshape(rows, cols).astype(np.int32)


def polygon_cells(polygons: np.ndarray, grid: MetricGrid) -> np.ndarray:
    """The cells of ``grid`` (bool) that convex polygons cover: (K, M, 2) or one (M, 2) corners,
    metres, in the grid's frame. OpenCV's fill with 8 fixed-point bits: the cells whose centres
    are inside and the cells the edges touch. Each polygon is filled on its own, so overlaps are
    covered (``cv2.fillPoly``'s even-odd rule would leave them out)."""
    shift = 8  # fixed-point bits: cell centres are at integer pixel coordinates
    polygons = np.asarray(polygons, dtype=np.float64)
    polygons = polygons.reshape(-1, *polygons.shape[-2:])
    uv = grid.xy_to_pixels(polygons.reshape(-1, 2)).reshape(polygons.shape)
    area = np.zeros(grid.shape, np.uint8)
    for poly in np.round(uv * (1 << shift)).astype(np.int32):
        cv2.fillConvexPoly(area, poly, 1, lineType=cv2.LINE_8, shift=shift)
    return area.astype(bool)


def points_to_grid(xy: np.ndarray, grid: MetricGrid, min_hits: int = 1,
                   move: Callable[[np.ndarray], np.ndarray] | None = None) -> np.ndarray:
    """Occupied cells: those holding at least ``min_hits`` of the points (N, 2, metres, grid
    frame, or moved into it by ``move`` as :func:`hit_counts` does). Bool."""
    return hit_counts(xy, grid, move) >= min_hits


def warp_state(state: np.ndarray, src: MetricGrid, tf: Similarity2D, dst: MetricGrid) -> np.ndarray:
    """Draw an occupancy raster (``state`` on grid ``src``, map frame) into grid ``dst`` (truth
    frame) under ``tf``: ``p_dst = tf(p_src)``. Cells outside the source are UNKNOWN.

    Occupied and known fractions are resampled with area averaging when the source is finer than
    the destination and bilinear interpolation otherwise; a cell is occupied when at least a third
    of it is, so one-cell walls survive any rotation.
    """
    # Area-average a much finer source down first: warpAffine alone would drop thin walls.
    # A source cell is src.resolution * tf.scale long in the destination's frame.
    factor = dst.resolution / (src.resolution * tf.scale)
    occ = (state == OCCUPIED).astype(np.float32)
    known = (state != UNKNOWN).astype(np.float32)
    if factor > 1.5:
        small = src.resampled(src.resolution * factor)
        size = (small.shape[1], small.shape[0])
        occ = cv2.resize(occ, size, interpolation=cv2.INTER_AREA)
        known = cv2.resize(known, size, interpolation=cv2.INTER_AREA)
        src = small
    # dst pixel -> dst metres -> src metres -> src pixel
    m = src.xy_to_pixel_matrix() @ tf.inverse().matrix @ dst.pixel_to_xy_matrix()
    size = (dst.shape[1], dst.shape[0])
    flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    occ_w = cv2.warpAffine(occ, m[:2], size, flags=flags, borderValue=0.0)
    known_w = cv2.warpAffine(known, m[:2], size, flags=flags, borderValue=0.0)
    out = np.full(dst.shape, UNKNOWN, dtype=np.int8)
    out[known_w >= 0.5] = FREE
    out[occ_w >= 1.0 / 3.0] = OCCUPIED
    return out
