"""The lines where two planes of a cloud meet (:func:`plane_lines`): the intersection line of
two planes at least :data:`MIN_CROSSING_DEG` apart whose extents touch within a margin, kept
as the segment that lies within both extents grown by that margin. A wall's foot on the
floor, the edge of two walls, a facade's edge on the ground. Metres, the planes' frame."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import connected_components

from pcmapq.features.planes3d import Planes, oriented

#: Two planes meet in a line only when their normals are at least this far apart, degrees:
#: nearly parallel planes (a step, a kerb's two faces) cross far from either, or nowhere.
MIN_CROSSING_DEG = 30.0


@dataclass(frozen=True)
class Lines:
    """L lines, metres. direction: (L, 3) unit directions, largest component positive.
    point: (L, 3) the middle of each segment. length: (L,) the segment's length."""

    direction: np.ndarray
    point: np.ndarray
    length: np.ndarray

    def __len__(self) -> int:
        return len(self.direction)

    @property
    def ends(self) -> np.ndarray:
        """(L, 2, 3) the segments' ends."""
        half = (self.length / 2)[:, None] * self.direction
        return np.stack([self.point - half, self.point + half], axis=1)


def no_lines() -> Lines:
    """Lines with no line in them."""
    return Lines(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0))


def _within(planes: Planes, k: np.ndarray, base: np.ndarray, direction: np.ndarray,
            margin: float) -> tuple[np.ndarray, np.ndarray]:
    """The span [t0, t1] (each (K,)) of ``base + t * direction`` (lines lying in planes ``k``)
    inside those planes' rectangles grown by ``margin`` (slab method; t0 > t1: none)."""
    axes = planes.axes[k]  # (K, 2, 3)
    half = planes.extent[k] / 2 + margin
    at = np.einsum("kaj,kj->ka", axes, base - planes.centre[k])
    step = np.einsum("kaj,kj->ka", axes, direction)
    flat = np.abs(step) < 1e-12
    safe = np.where(flat, 1.0, step)
    a, b = (-half - at) / safe, (half - at) / safe
    lo = np.where(flat, np.where(np.abs(at) <= half, -np.inf, np.inf), np.minimum(a, b))
    hi = np.where(flat, np.where(np.abs(at) <= half, np.inf, -np.inf), np.maximum(a, b))
    return lo.max(axis=1), hi.min(axis=1)


def plane_lines(planes: Planes, margin: float, min_length: float = 0.0) -> Lines:
    """The lines where two of ``planes`` meet: each pair at least :data:`MIN_CROSSING_DEG`
    apart whose rectangles, grown by ``margin`` metres, both hold a piece of their
    intersection line at least ``min_length`` metres long; that piece is the line's segment.
    One line where several pairs give it (a wall on two pieces of one floor): the union of
    their segments. In the order of the pairs (the planes' order)."""
    i, j = np.triu_indices(len(planes), k=1)
    n = planes.normal
    cross = np.cross(n[i], n[j])
    sine = np.linalg.norm(cross, axis=1)
    keep = sine >= np.sin(np.radians(MIN_CROSSING_DEG))
    i, j, cross, sine = i[keep], j[keep], cross[keep], sine[keep]
    if not len(i):
        return no_lines()
    direction = oriented(cross / sine[:, None])
    # the point of both planes nearest the origin: n_i.x = d_i, n_j.x = d_j, direction.x = 0
    rows = np.stack([n[i], n[j], direction], axis=1)
    rhs = np.stack([planes.offset[i], planes.offset[j], np.zeros(len(i))], axis=1)
    base = np.linalg.solve(rows, rhs[:, :, None])[:, :, 0]
    lo_i, hi_i = _within(planes, i, base, direction, margin)
    lo_j, hi_j = _within(planes, j, base, direction, margin)
    lo, hi = np.maximum(lo_i, lo_j), np.minimum(hi_i, hi_j)
    ok = hi - lo > 0
    return _merged(direction[ok], base[ok], lo[ok], hi[ok], margin, min_length)


def _merged(direction: np.ndarray, base: np.ndarray, lo: np.ndarray, hi: np.ndarray,
            near: float, min_length: float) -> Lines:
    """Lines ``base + t * direction``, t in [lo, hi], with those that are one line (within
    1 degree and ``near`` metres of each other, their segments overlapping) made one: the
    union of their segments, on the line of the longest (the first of equals): a sliver
    where two rectangles merely touch within the margin does not carry a long line to its
    plane; then those at least ``min_length``."""
    count = len(direction)
    a, b = np.triu_indices(count, k=1)
    same = np.abs(np.einsum("ij,ij->i", direction[a], direction[b])) >= \
        np.cos(np.radians(1.0))
    gap = base[b] - base[a]
    apart = np.linalg.norm(gap - np.einsum("ij,ij->i", gap, direction[a])[:, None]
                           * direction[a], axis=1)
    # b's segment along a's line
    shift = np.einsum("ij,ij->i", gap, direction[a])
    turn = np.sign(np.einsum("ij,ij->i", direction[a], direction[b]))
    b_lo = shift + np.minimum(turn * lo[b], turn * hi[b])
    b_hi = shift + np.maximum(turn * lo[b], turn * hi[b])
    overlap = (np.minimum(hi[a], b_hi) >= np.maximum(lo[a], b_lo))
    keep = same & (apart <= near) & overlap
    graph = sparse.coo_array((np.ones(int(keep.sum())), (a[keep], b[keep])),
                             shape=(count, count))
    _, group = connected_components(graph, directed=False)
    # each line's group's head: its longest line, the first of equals
    rank = np.empty(count, dtype=np.int64)
    rank[np.lexsort((np.arange(count), lo - hi))] = np.arange(count)
    best = np.full(count, count)
    np.minimum.at(best, group, rank)
    head = np.argsort(rank)[best[group]]
    gap = base - base[head]
    shift = np.einsum("ij,ij->i", gap, direction[head])
    turn = np.sign(np.einsum("ij,ij->i", direction[head], direction))
    s_lo = shift + np.minimum(turn * lo, turn * hi)
    s_hi = shift + np.maximum(turn * lo, turn * hi)
    g_lo, g_hi = np.full(count, np.inf), np.full(count, -np.inf)
    np.minimum.at(g_lo, head, s_lo)
    np.maximum.at(g_hi, head, s_hi)
    heads = np.flatnonzero(head == np.arange(count))
    length = g_hi[heads] - g_lo[heads]
    middle = base[heads] + ((g_lo[heads] + g_hi[heads]) / 2)[:, None] * direction[heads]
    ok = length >= max(min_length, 1e-9)
    return Lines(direction[heads][ok], middle[ok], length[ok])
