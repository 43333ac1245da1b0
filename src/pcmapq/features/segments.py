"""Geometry of wall segments (N, 4) ``x0, y0, x1, y1`` in metres: directions, which segments
come near each other, and where segments run inside a wall (for the Hough detector; merging
collinear fragments is :mod:`pcmapq.features.merging`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import affine


def directions(seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (N, 2) and lengths (N,) of segments (N, 4)."""
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    return d / np.maximum(length, 1e-12)[:, None], length


@dataclass(frozen=True)
class WallTest:
    """Whether points (..., 2), metres, fall on cells of ``image`` of at least ``level``
    (bool, same leading shape); ``to_pixels``: the image grid's metres -> pixels matrix (3, 3).
    Points outside the image are not in a wall."""

    image: np.ndarray
    to_pixels: np.ndarray
    level: float

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        rows, cols = self.image.shape
        m = self.to_pixels
        uv = np.floor(affine(xy.reshape(-1, 2), m) + 0.5).astype(np.int64)
        inside = (uv[:, 0] >= 0) & (uv[:, 0] < cols) & (uv[:, 1] >= 0) & (uv[:, 1] < rows)
        out = np.zeros(len(uv), dtype=bool)
        out[inside] = self.image[uv[inside, 1], uv[inside, 0]] >= self.level
        return out.reshape(xy.shape[:-1])


def wall_test(image: np.ndarray, work: MetricGrid, level: float) -> WallTest:
    """Whether points fall on cells of ``image`` (on grid ``work``) of at least ``level``."""
    return WallTest(image, work.xy_to_pixel_matrix(), float(level))


def _points(seg: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Points (M, 2) every ``step`` along segments (N, 4), both ends included, and the index of
    the segment of each (M,)."""
    d, length = directions(seg)
    n = np.floor(length / step).astype(np.int64) + 2
    which = np.repeat(np.arange(len(seg)), n)
    t = np.minimum((np.arange(n.sum()) - (np.cumsum(n) - n)[which]) * step, length[which])
    return seg[which, :2] + t[:, None] * d[which], which


def near_pairs(a: np.ndarray, b: np.ndarray, distance: float) -> tuple[np.ndarray, np.ndarray]:
    """Every pair of segments of ``a`` (N, 4) and ``b`` (M, 4) that come within ``distance`` of
    each other, and some up to twice as far (they are sampled every ``distance``): indices
    (i, j) into ``a`` and ``b``, sorted by i, then j. Metres."""
    if len(a) == 0 or len(b) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    (pa, owner_a), (pb, owner_b) = _points(a, distance), _points(b, distance)
    # every point of a segment is within half a step of one of its samples
    near = cKDTree(pa).sparse_distance_matrix(cKDTree(pb), 2 * distance,
                                              output_type="coo_matrix")
    pair = np.unique(owner_a[near.row] * len(b) + owner_b[near.col])
    return pair // len(b), pair % len(b)


def away(xy: np.ndarray, seg: np.ndarray, distance: float, step: float) -> np.ndarray:
    """(N,) bool: which points ``xy`` (N, 2) are farther than ``distance`` from every segment
    (M, 4) (tested at points every ``step`` along them). Metres."""
    if len(seg) == 0 or len(xy) == 0:
        return np.ones(len(xy), dtype=bool)
    # many more samples than points asked about: the tree's build is most of the work, and a
    # tree split at midpoints builds in less than half the time and gives the same distances
    tree = cKDTree(_points(seg, step)[0], balanced_tree=False, compact_nodes=False)
    dist, _ = tree.query(xy, distance_upper_bound=distance)
    return ~np.isfinite(dist)


def inside_runs(seg: np.ndarray, inside: Callable[[np.ndarray], np.ndarray], step: float,
                shortest: float) -> np.ndarray:
    """The parts of segments (N, 4, metres) along which ``inside(xy)`` holds at every point
    tested (every ``step`` metres), at least ``shortest`` metres long: (M, 4) metres."""
    d, length = directions(seg)
    n = np.floor(length / step).astype(np.int64) + 1  # points per segment
    which = np.repeat(np.arange(len(seg)), n)
    first = np.cumsum(n) - n
    t = (np.arange(n.sum()) - first[which]) * step  # along each segment, metres
    ok = inside(seg[which, :2] + t[:, None] * d[which])
    new = np.ones(len(ok), dtype=bool)
    new[first] = True
    new[1:] &= ~ok[:-1] | (which[1:] != which[:-1])  # run starts: no inside point before it
    last = np.ones(len(ok), dtype=bool)
    last[:-1] = ~ok[1:] | (which[1:] != which[:-1])  # run ends: no inside point after it
    start, end = np.flatnonzero(ok & new), np.flatnonzero(ok & last)  # paired, in order
    keep = t[end] - t[start] >= shortest
    start, end = start[keep], end[keep]
    k = which[start]
    return np.column_stack([seg[k, :2] + t[start, None] * d[k], seg[k, :2] + t[end, None] * d[k]])
