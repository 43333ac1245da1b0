"""Moment sums over every point's ball (its map points strictly closer than a radius, itself
included), on a uniform grid of columns of side ``radius`` and a compiled loop over candidates.

The points are sorted by column (square cells across the two shorter axes) and, within one,
along the longest axis, so a point's candidates are, in each of the 3 x 3 columns around its
own, one contiguous range: the points within the radius of it along that axis (a column
farther than the radius across is skipped, and a nearer one's range narrowed to the chord
left). Each candidate is decided exactly as Open3D's search does, ((dx dx + dy dy) + dz dz) <
radius^2 in the map's own coordinates (no fused multiply-add), with margins of a millionth of
the radius on the ranges so that no candidate the test would keep is left out. A point's sums
(1, dx, dy, dz, dx dx, dx dy, dx dz, dy dy, dy dz, dz dz of its neighbours' offsets from it)
are added by one thread in sorted order, so they are the same bit for bit whatever the number
of threads. Numba compiles the loop on first use and caches it on disk.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numba
import numpy as np

#: Numba's threading layers in the order tried: OpenMP, then its own work queue (the TBB found
#: beside some installs is too old, and Numba warns when it tries it first).
numba.config.THREADING_LAYER_PRIORITY = ["omp", "workqueue", "tbb"]

#: Points whose sums one yield holds (80 bytes each; the covariances, determinants and
#: eigenvalues found from them hold about four times that beside them).
CHUNK_POINTS = 100_000
#: The 3 x 3 columns around a column: offsets across the two shorter axes.
OFFSETS = np.array([(d0, d1) for d0 in (-1, 0, 1) for d1 in (-1, 0, 1)], dtype=np.int64)


def moments(xyz: np.ndarray) -> np.ndarray:
    """(N, 3) metres -> (N, 10): 1, x, y, z, xx, xy, xz, yy, yz, zz."""
    x, y, z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    return np.column_stack([np.ones(len(xyz)), x, y, z, x * x, x * y, x * z, y * y, y * z, z * z])


class _Grid:
    """Points sorted by column (cells of side ``radius`` across the two shorter axes ``axes[:2]``)
    and, within one, along the longest axis ``axes[2]``; per point, the rank of its column;
    per column, its two cell indices and the [start, end) of each of its 3 x 3 neighbouring
    columns in sorted order (empty where there are no points)."""

    def __init__(self, pts: np.ndarray, radius: float) -> None:
        # Built an axis at a time, with no temporary of all the points beside those kept: a
        # large map's peak holds its points once.
        self.axes = np.argsort(np.ptp(pts, axis=0), kind="stable")  # longest axis last
        self.low = pts.min(axis=0)[self.axes[:2]]
        i, j = (np.floor((pts[:, a] - low) / radius).astype(np.int64) + 1
                for a, low in zip(self.axes[:2], self.low, strict=True))
        dim1 = int(j.max()) + 2
        if (int(i.max()) + 2) * dim1 >= 2**62:
            raise ValueError(f"radius {radius} m is too small for the map's extent")
        col = i * dim1 + j
        del i, j
        self.order = np.lexsort((pts[:, self.axes[2]], col))
        self.xyz = np.empty((3, len(pts)))
        for axis in range(3):
            self.xyz[axis] = pts[self.order, axis]
        col = col[self.order]
        # the columns' runs in sorted order: np.unique(col, return_index, return_counts)
        starts = np.flatnonzero(np.concatenate(([True], col[1:] != col[:-1])))
        cols = col[starts]
        counts = np.diff(np.append(starts, len(col)))
        del col
        self.rank = np.repeat(np.arange(len(cols)), counts)
        self.cell = np.column_stack([cols // dim1, cols % dim1])
        ends = starts + counts
        other = cols[:, None] + OFFSETS[:, 0] * dim1 + OFFSETS[:, 1]
        r = np.minimum(np.searchsorted(cols, other), len(cols) - 1)
        there = cols[r] == other
        self.lo = np.where(there, starts[r], 0)
        self.hi = np.where(there, ends[r], 0)


@numba.njit(cache=True, inline="always")
def _first(w: np.ndarray, lo: int, hi: int, value: float) -> int:
    """The first index in [lo, hi) of sorted ``w`` whose value is not below ``value`` (hi if
    none): a binary search without branches on the data."""
    n = hi - lo
    while n > 0:
        half = n // 2
        below = w[lo + half] < value
        lo = lo + half + 1 if below else lo
        n = n - half - 1 if below else half
    return lo


@numba.njit(cache=True)
def _d2(dx: float, dy: float, dz: float) -> float:
    """Squared distance as Open3D sums it (a function of its own: no reassociation here)."""
    return (dx * dx + dy * dy) + dz * dz


@numba.njit(cache=True, fastmath={"reassoc", "nsz"})
def _span(xs: np.ndarray, ys: np.ndarray, zs: np.ndarray, start: int, end: int, x: float,
          y: float, z: float, r2: float) -> tuple[float, ...]:
    """Moment sums of the points [start, end) closer than sqrt(r2) to (x, y, z), offsets from
    it (the sums vectorised: their order of additions is fixed by the machine's vector width,
    not by the threads)."""
    s1 = sx = sy = sz = sxx = sxy = sxz = syy = syz = szz = 0.0
    for t in range(np.uint64(start), np.uint64(end)):  # unsigned: no wraparound test
        dx, dy, dz = xs[t] - x, ys[t] - y, zs[t] - z
        near = _d2(x - xs[t], y - ys[t], z - zs[t]) < r2
        dx = dx if near else 0.0
        dy = dy if near else 0.0
        dz = dz if near else 0.0
        s1 += 1.0 if near else 0.0
        sx += dx
        sy += dy
        sz += dz
        sxx += dx * dx
        sxy += dx * dy
        sxz += dx * dz
        syy += dy * dy
        syz += dy * dz
        szz += dz * dz
    return s1, sx, sy, sz, sxx, sxy, sxz, syy, syz, szz


@numba.njit(cache=True, parallel=True, nogil=True)
def _sums(xyz: np.ndarray, axes: np.ndarray, low: np.ndarray, rank: np.ndarray,
          cell: np.ndarray, lo: np.ndarray, hi: np.ndarray, radius: float, rows: np.ndarray,
          out: np.ndarray) -> None:
    """Sums of the points ``rows[k]`` (sorted order) into ``out[k]``. ``xyz``: the sorted
    map's coordinates (3, N); ``axes``: its rows along the grid's axes, longest last."""
    r2 = radius * radius
    xs, ys, zs = xyz[0], xyz[1], xyz[2]
    us, vs, ws = xyz[axes[0]], xyz[axes[1]], xyz[axes[2]]
    margin = 1e-6 * radius + 64.0 * np.finfo(np.float64).eps * max(np.abs(xyz).max(), radius)
    for row in numba.prange(out.shape[0]):
        i = rows[row]
        u, v, w = us[i], vs[i], ws[i]
        c = rank[i]
        acc = np.zeros(10)
        for k in range(OFFSETS.shape[0]):
            if hi[c, k] <= lo[c, k]:
                continue
            # the gaps across from the point to the column's cell, less the margin
            c0 = low[0] + (cell[c, 0] + OFFSETS[k, 0] - 1) * radius
            c1 = low[1] + (cell[c, 1] + OFFSETS[k, 1] - 1) * radius
            g0 = max(c0 - u, u - (c0 + radius), 0.0) - margin
            g1 = max(c1 - v, v - (c1 + radius), 0.0) - margin
            h2 = max(g0, 0.0) ** 2 + max(g1, 0.0) ** 2
            if h2 >= r2:
                continue
            half = math.sqrt(r2 - h2) + margin
            start = _first(ws, lo[c, k], hi[c, k], w - half)
            end = _first(ws, start, hi[c, k], w + half)
            part = _span(xs, ys, zs, start, end, xs[i], ys[i], zs[i], r2)
            for m in range(10):
                acc[m] += part[m]
        out[row] = acc


def ball_sums(points: np.ndarray, radius: float, chunk_points: int = CHUNK_POINTS,
              workers: int | None = None,
              queries: np.ndarray | None = None) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Yield (indices into ``points``, (k, 10) moment sums) over the neighbourhood (points with
    |p - q| < ``radius`` metres) of every point, or of the points ``queries`` (distinct indices
    into ``points``) only: count, sums of x, y, z, xx, xy, xz, yy, yz, zz of the neighbours' offsets
    from the point itself. Chunks of about ``chunk_points`` points, in an order and with figures
    independent of ``workers`` (threads; default Numba's, at most its ``NUMBA_NUM_THREADS``);
    a point's sums are the same whether it is one of ``queries`` or not. Memory: the sorted map
    and one chunk's sums."""
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) == 0:
        return
    grid = _Grid(pts, radius)
    if queries is None:
        rows = np.arange(len(pts), dtype=np.int64)
    else:  # the sorted positions of the queries, in order (a byte a point, not an index)
        asked = np.zeros(len(pts), dtype=bool)
        asked[np.asarray(queries, dtype=np.int64)] = True
        rows = np.flatnonzero(asked[grid.order])
    threads = min(workers or numba.get_num_threads(), numba.config.NUMBA_NUM_THREADS)
    step = max(1, chunk_points)
    for p0 in range(0, len(rows), step):
        chunk = rows[p0:p0 + step]
        out = np.empty((len(chunk), 10))
        before = numba.get_num_threads()
        numba.set_num_threads(max(1, threads))
        try:
            _sums(grid.xyz, grid.axes, grid.low, grid.rank, grid.cell, grid.lo, grid.hi,
                  float(radius), chunk, out)
        finally:
            numba.set_num_threads(before)
        yield grid.order[chunk], out
