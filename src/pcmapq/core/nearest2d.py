"""Exact nearest neighbours in the plane within a distance, on a grid of buckets: for the 2D
ICPs, which ask for the nearest truth point of a few thousand map points at a time, thousands
of times, where a KD-tree's per-call and per-point costs dominate.

A query point's nearest point is searched ring by ring of buckets around its own, until no
bucket left can hold a point nearer than the nearest found or nearer than the distance asked:
the point a KD-tree finds (of points at exactly the same distance, the first listed). Metres,
in the points' frame.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["NearestGrid"]

#: Buckets at most, per point held (a sparse set of points spread far gets larger buckets).
BUCKETS_PER_POINT = 4
#: Buckets at most whatever the points (an array of this many int64 bucket starts).
MOST_BUCKETS = 1 << 22


class NearestGrid:
    """The points (M, 2) in square buckets of ``bucket`` metres (at least; larger where the
    points spread too far for BUCKETS_PER_POINT buckets per point)."""

    def __init__(self, points: np.ndarray, bucket: float = 0.25) -> None:
        self.points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        n = len(self.points)
        self.low = self.points.min(axis=0) if n else np.zeros(2)
        span = (self.points.max(axis=0) - self.low) if n else np.zeros(2)
        most = max(min(BUCKETS_PER_POINT * n, MOST_BUCKETS), 1)
        self.bucket = float(max(bucket, np.sqrt(float((span[0] + bucket) * (span[1] + bucket))
                                                / most)))
        self.shape = (np.floor(span / self.bucket).astype(np.int64) + 1)
        cell = np.floor((self.points - self.low) / self.bucket).astype(np.int64)
        code = cell[:, 0] * self.shape[1] + cell[:, 1]
        self.order = np.argsort(code, kind="stable")  # within a bucket, in the points' order
        self.starts = np.searchsorted(code[self.order],
                                      np.arange(int(self.shape.prod()) + 1)).astype(np.int64)
        self.sorted = np.ascontiguousarray(self.points[self.order])

    def nearest(self, query: np.ndarray, max_distance: float) -> np.ndarray:
        """(K,) the index of each query point's (K, 2) nearest point, -1 where none lies
        nearer than ``max_distance`` metres."""
        query = np.ascontiguousarray(query, dtype=np.float64).reshape(-1, 2)
        found = np.full(len(query), -1, dtype=np.int64)
        if len(self.points):
            _nearest(query, self.sorted, self.order, self.starts, self.low, self.bucket,
                     self.shape[0], self.shape[1], max_distance, found)
        return found


@numba.njit(cache=True, nogil=True)
def _nearest(query, points, order, starts, low, bucket, nx, ny, max_distance, found):
    """Ring-by-ring search of each query point's nearest point (see the module's docstring)."""
    reach2 = max_distance * max_distance
    for q in range(len(query)):
        x = (query[q, 0] - low[0]) / bucket
        y = (query[q, 1] - low[1]) / bucket
        cx, cy = int(np.floor(x)), int(np.floor(y))
        best, best_at = reach2, -1
        ring = 0
        while True:
            for ix in range(cx - ring, cx + ring + 1):
                if ix < 0 or ix >= nx:
                    continue
                edge = ix == cx - ring or ix == cx + ring
                step = 1 if edge else 2 * ring
                iy = cy - ring
                while iy <= cy + ring:
                    if 0 <= iy < ny:
                        b = ix * ny + iy
                        for s in range(starts[b], starts[b + 1]):
                            dx = points[s, 0] - query[q, 0]
                            dy = points[s, 1] - query[q, 1]
                            d2 = dx * dx + dy * dy
                            if d2 < best or (d2 == best and best_at >= 0
                                             and order[s] < best_at):
                                best, best_at = d2, order[s]
                    iy += step
            # the nearest any bucket outside the rings searched can hold
            gap = min(x - (cx - ring), cx + ring + 1 - x, y - (cy - ring),
                      cy + ring + 1 - y) * bucket
            if gap > 0 and gap * gap > best:
                break
            if cx - ring <= 0 and cy - ring <= 0 and cx + ring >= nx - 1 and cy + ring >= ny - 1:
                break
            ring += 1
        found[q] = best_at
