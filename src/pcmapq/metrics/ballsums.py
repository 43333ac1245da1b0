"""Moment sums over every point's ball (its map points strictly closer than a radius, itself
included), on a uniform grid of cells of side ``radius`` and dense distance blocks.

The points are sorted by cell (the longest axis varying fastest), and consecutive cells of one
column along that axis are taken together as a *block* (at least ``MIN_BLOCK_POINTS`` points
when the map is sparse). A block's candidate neighbours are the points of the cells within the
radius of it, which the sort makes a few contiguous ranges. Squared distances come from one
matrix product, d^2 = |a|^2 + |b|^2 - 2 a.b in coordinates relative to the block's mean; a
candidate whose d^2 lies within a rounding bound of radius^2 is decided again exactly as
Open3D's search does, ((dx dx + dy dy) + dz dz) < radius^2 in the map's own coordinates. The
sums are a second matrix product, the 0/1 neighbour matrix times the candidates' moments
(1, x, y, z, xx, xy, xz, yy, yz, zz relative to the block's mean). Both products are kept
below OpenBLAS's threading threshold (``BLOCK`` candidates a product), so BLAS runs on the
calling thread: threads of our own run the blocks, and the figures do not depend on how many.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from threadpoolctl import threadpool_limits

#: Candidate pairs in one product (8 bytes each, a few arrays of them per thread).
BLOCK = 2000000
#: Columns across one radius, and the most points of a block.
SPLIT = 1
BLOCK_POINTS = 96
#: Points whose sums one yield holds (80 bytes each).
CHUNK_POINTS = 1_000_000
#: Threads over blocks by default (CI machines have two cores).
WORKERS = 2
#: Rounding bound factor: |computed - exact| d^2 stays within TOL * eps * (scale) for 3 terms.
TOL = 16.0


def moments(xyz: np.ndarray) -> np.ndarray:
    """(N, 3) metres -> (N, 10): 1, x, y, z, xx, xy, xz, yy, yz, zz."""
    x, y, z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    return np.column_stack([np.ones(len(xyz)), x, y, z, x * x, x * y, x * z, y * y, y * z, z * z])


def _columns(split: int) -> list[tuple[int, int]]:
    """Offsets of the columns (side radius / ``split``) that come closer than one radius to a
    column."""
    reach = range(-split, split + 1)
    return [(d0, d1) for d0 in reach for d1 in reach
            if max(abs(d0) - 1, 0) ** 2 + max(abs(d1) - 1, 0) ** 2 < split * split]


class _Grid:
    """Points sorted by column (square cells of side ``radius / SPLIT`` across the two shorter
    axes) and, within one, along the longest axis; the blocks ([start, end) in sorted order, at
    most ``BLOCK_POINTS`` consecutive points of one column) and their candidate ranges (``lo``,
    ``hi``: one per neighbouring column, the points within ``radius`` of the block along the
    longest axis)."""

    def __init__(self, pts: np.ndarray, radius: float) -> None:
        axes = np.argsort(np.ptp(pts, axis=0), kind="stable")  # longest axis last
        low = pts.min(axis=0)
        side = radius / SPLIT
        ij = np.floor((pts[:, axes[:2]] - low[axes[:2]]) / side).astype(np.int64) + SPLIT
        dim1 = int(ij[:, 1].max()) + SPLIT + 1
        if (int(ij[:, 0].max()) + SPLIT + 1) * dim1 >= 2**62:
            raise ValueError(f"radius {radius} m is too small for the map's extent")
        col = ij[:, 0] * dim1 + ij[:, 1]
        z = pts[:, axes[2]] - low[axes[2]]
        self.order = np.lexsort((z, col))
        self.points = pts[self.order]
        col, z = col[self.order], z[self.order]
        cols, starts, counts = np.unique(col, return_index=True, return_counts=True)
        rank = np.repeat(np.arange(len(cols)), counts)
        pos = np.arange(len(col)) - np.repeat(starts, counts)
        first = np.flatnonzero(pos % BLOCK_POINTS == 0)
        self.start = first
        self.end = np.r_[first[1:], len(col)]
        # one sorted float key per point: its column's rank, then its place along the axis
        width = float(z.max()) + 4.0 * radius + 1.0
        key = rank * width + z
        margin = 8.0 * np.finfo(float).eps * (len(cols) * width) + 1e-9 * radius
        zlo, zhi = z[self.start] - radius - margin, z[self.end - 1] + radius + margin
        bcol = col[self.start]
        lo, hi = [], []
        for d0, d1 in _columns(SPLIT):
            other = bcol + d0 * dim1 + d1
            r = np.minimum(np.searchsorted(cols, other), len(cols) - 1)
            there = cols[r] == other
            lo.append(np.where(there, np.searchsorted(key, r * width + zlo, "left"), 0))
            hi.append(np.where(there, np.searchsorted(key, r * width + zhi, "right"), 0))
        self.lo = np.stack(lo, axis=1)
        self.hi = np.stack(hi, axis=1)


def _block(grid: _Grid, k: int, r2: float, out: np.ndarray, p0: int) -> None:
    """Sums of block ``k`` into ``out`` (row i: the point at ``p0 + i`` in sorted order)."""
    pts = grid.points
    a0, a1 = int(grid.start[k]), int(grid.end[k])
    spans = [(int(s), int(e)) for s, e in zip(grid.lo[k], grid.hi[k], strict=True) if e > s]
    a_abs = pts[a0:a1]
    b_abs = np.concatenate([pts[s:e] for s, e in spans])
    centre = a_abs.mean(axis=0)
    a = a_abs - centre
    b = b_abs - centre
    f = moments(b)
    aa = np.einsum("ij,ij->i", a, a)
    bb = np.einsum("ij,ij->i", b, b)
    tol = TOL * np.finfo(float).eps * (2.0 * aa.max() + 2.0 * bb.max() + r2)
    aa -= r2
    bt = np.ascontiguousarray(-2.0 * b.T)
    rows = max(1, BLOCK // max(len(b), 10))
    for i in range(0, len(a), rows):
        d = a[i:i + rows] @ bt
        d += aa[i:i + rows, None]
        d += bb
        near = d < tol
        if np.count_nonzero(near) != np.count_nonzero(d < -tol):
            _exact(near, d > -tol, a_abs[i:i + rows], b_abs, r2)
        out[a0 - p0 + i:a0 - p0 + i + len(d)] = near.astype(np.float64) @ f


def _blocks(grid: _Grid, r2: float, out: np.ndarray, p0: int, ks: np.ndarray) -> None:
    for k in ks:
        _block(grid, int(k), r2, out, p0)


def _exact(near: np.ndarray, band: np.ndarray, a: np.ndarray, b: np.ndarray, r2: float) -> None:
    """Decide the candidates within rounding of the radius as Open3D does (in place)."""
    ii, jj = np.nonzero(near & band)
    diff = a[ii] - b[jj]
    d2 = (diff[:, 0] * diff[:, 0] + diff[:, 1] * diff[:, 1]) + diff[:, 2] * diff[:, 2]
    near[ii, jj] = d2 < r2


def ball_sums(points: np.ndarray, radius: float, chunk_points: int = CHUNK_POINTS,
              workers: int | None = None) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Yield (indices into ``points``, (k, 10) moment sums) over every point's neighbourhood
    (points with |p - q| < ``radius`` metres): count, sums of x, y, z, xx, xy, xz, yy, yz, zz
    relative to an origin of its own block. Chunks of about ``chunk_points`` points, in an
    order and with figures independent of ``workers`` (threads). Memory: the sorted map, one
    chunk's sums and ``workers`` blocks of ``BLOCK`` candidates."""
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) == 0:
        return
    grid = _Grid(pts, radius)
    r2 = radius * radius
    workers = max(1, workers or min(WORKERS, os.cpu_count() or 1))
    n_blocks = len(grid.start)
    bounds = np.searchsorted(grid.start, np.arange(0, len(pts), max(1, chunk_points)))
    bounds = np.unique(np.r_[bounds, n_blocks])
    with ThreadPoolExecutor(workers) as pool:
        for c0, c1 in zip(bounds[:-1], bounds[1:], strict=True):
            p0, p1 = int(grid.start[c0]), int(grid.end[c1 - 1])
            out = np.empty((p1 - p0, 10))
            parts = np.array_split(np.arange(c0, c1), min(c1 - c0, workers * 8))
            with threadpool_limits(1, user_api="blas"):  # its own threads busy-wait beside ours
                list(pool.map(functools.partial(_blocks, grid, r2, out, p0), parts))
            yield grid.order[p0:p1], out
