"""Geometry of wall segments (N, 4) ``x0, y0, x1, y1`` in metres: directions, merging
collinear fragments into maximal walls, and where segments run inside a wall (for the Hough
detector)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.grid import MetricGrid


def directions(seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (N, 2) and lengths (N,) of segments (N, 4)."""
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    return d / np.maximum(length, 1e-12)[:, None], length


#: Regroup-and-refit rounds of one merged segment.
_REFITS = 4
#: Points tested along a gap to bridge.
_BRIDGE_SAMPLES = 16


def _line(ends: np.ndarray, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weighted total-least-squares line through segment endpoints ``ends`` (K, 2, 2), each
    segment weighted by ``weight`` (K,): a point on it (2,) and its unit direction (2,)."""
    pts = ends.reshape(-1, 2)
    w = np.repeat(weight, 2)
    centre = w @ pts / w.sum()
    r = pts - centre
    cov = (r * w[:, None]).T @ r
    angle = 0.5 * np.arctan2(2 * cov[0, 1], cov[0, 0] - cov[1, 1])  # principal axis
    return centre, np.array([np.cos(angle), np.sin(angle)])


def _grow(t: np.ndarray, fits: np.ndarray, group: np.ndarray, max_gap: float,
          max_bridge: float, bridged: Callable[[np.ndarray, np.ndarray], np.ndarray]
          ) -> np.ndarray:
    """The group extended by every fitting segment near its extent along the line, repeatedly,
    as the extent grows.

    ``t`` (N, 2) are the endpoint positions along the line, metres. A segment is near when the
    gap between it and the group is at most ``max_gap``, or at most ``max_bridge`` when
    ``bridged(start, end)`` says the wall is solid over the gap (positions along the line,
    metres, one pair per segment).
    """
    a, b = t.min(axis=1), t.max(axis=1)
    while True:
        lo, hi = t[group].min(), t[group].max()
        above = a > hi
        start, end = np.where(above, hi, b), np.where(above, a, lo)
        gap = np.where(above | (b < lo), end - start, 0.0)
        near = fits & ~group & (gap <= max_gap)
        far = np.flatnonzero(fits & ~group & ~near & (gap <= max_bridge))
        if len(far):
            near[far] = bridged(start[far], end[far])
        if not near.any():
            return group
        group = group | near


#: Tiles a side of the index of :func:`merge`'s segments.
_TILES = 64


class _Index:
    """Segments (N, 4, metres) bucketed by the square tile holding their midpoint, so that
    those near a line are found without testing them all."""

    def __init__(self, seg: np.ndarray) -> None:
        mid = 0.5 * (seg[:, :2] + seg[:, 2:])
        lo = mid.min(axis=0)
        self.size = max(float(np.ptp(mid, axis=0).max()) / _TILES, 1e-9)
        cell = np.floor((mid - lo) / self.size).astype(np.int64)
        shape = cell.max(axis=0) + 1
        tile = cell[:, 0] * shape[1] + cell[:, 1]
        self.order = np.argsort(tile, kind="stable")
        counts = np.bincount(tile, minlength=int(np.prod(shape)))
        self.filled = np.flatnonzero(counts)
        self.counts = counts[self.filled]
        self.starts = (np.cumsum(counts) - counts)[self.filled]
        ix, iy = np.divmod(self.filled, shape[1])
        self.centres = lo + (np.column_stack([ix, iy]) + 0.5) * self.size

    def near_line(self, point: np.ndarray, normal: np.ndarray, width: float) -> np.ndarray:
        """Sorted indices of every segment whose midpoint may lie within ``width`` metres of
        the line through ``point`` with unit ``normal`` (and of some beyond it)."""
        reach = width + self.size / np.sqrt(2.0)  # a midpoint is this near its tile's centre
        hit = np.abs((self.centres - point) @ normal) <= reach
        starts, counts = self.starts[hit], self.counts[hit]
        first = np.repeat(starts - (np.cumsum(counts) - counts), counts)
        return np.sort(self.order[first + np.arange(counts.sum())])


def merge(seg: np.ndarray, max_angle: float, max_offset: float, max_gap: float,
          solid: Callable[[np.ndarray], np.ndarray] | None = None,
          max_bridge: float = 0.0) -> np.ndarray:
    """Merge collinear fragments into maximal segments.

    Longest first, each remaining segment seeds a group that absorbs every fragment within
    ``max_angle`` of the group's line direction, ``max_offset`` of the line and ``max_gap`` of
    its extent along it (or up to ``max_bridge`` away when the wall is solid all along the gap);
    the line is then refitted to the group (weighted total least squares of the endpoints) and
    the group regathered, a few rounds. Fragments are compared with the group's line, not with
    each other, so a chain of slightly turning fragments cannot drift. Only fragments within
    twice ``max_angle`` and twice ``max_offset`` of the seed's line are considered (the group's
    line stays near its seed's; this keeps large maps fast). The merged segments are merged
    again until nothing changes.

    Parameters
    ----------
    seg : (N, 4) segments, metres.
    max_angle : largest direction difference, degrees.
    max_offset : largest distance of a fragment's endpoints from the group's line, metres.
    max_gap : largest gap along the line between the group's extent and a fragment, metres.
    solid : ``solid(xy)``: whether the points (..., 2), metres, are inside a wall (bool, same
        leading shape); None: never.
    max_bridge : largest gap bridged where ``solid`` holds all along it, metres.

    Returns
    -------
    (M, 4) merged segments: each group's fitted line, spanning all of its endpoints. Metres,
    M <= N.
    """
    d, length = directions(seg)
    ends = np.stack([seg[:, :2], seg[:, 2:]], axis=1)  # (N, 2, 2)
    cos_max = np.cos(np.radians(max_angle))
    cos_near = np.cos(np.radians(min(2 * max_angle, 90.0)))
    steps = np.linspace(0.0, 1.0, _BRIDGE_SAMPLES)
    bridge = max_bridge if solid is not None else -np.inf  # no gap is bridged without solid
    left = np.ones(len(seg), dtype=bool)
    index = _Index(seg) if len(seg) else None
    out = []
    for seed in np.lexsort((seg[:, 1], seg[:, 0], -length)):  # longest first
        if not left[seed]:
            continue
        # the group's line stays near its seed's: only fragments within twice the angle and
        # offset of the seed's line can join (this keeps the loop cheap on large maps); the
        # index hands over those whose midpoints may be that near (both ends being so)
        u = d[seed]
        normal = np.array([-u[1], u[0]])
        near = index.near_line(ends[seed, 0], normal, 2 * max_offset)
        off = np.abs((ends[near] - ends[seed, 0]) @ normal).max(axis=1)
        near = near[left[near] & (np.abs(d[near] @ u) >= cos_near) & (off <= 2 * max_offset)]
        e, dn, ln = ends[near], d[near], length[near]
        group = near == seed
        for _ in range(_REFITS if len(near) > 1 else 0):  # a lone seed is its own group
            centre, u = _line(e[group], ln[group])

            def bridged(start: np.ndarray, end: np.ndarray, centre=centre, u=u) -> np.ndarray:
                pos = start[:, None] + (end - start)[:, None] * steps  # (K, S) along the line
                return solid(centre + pos[..., None] * u).all(1)

            t = (e - centre) @ u  # (K, 2) along the line
            off = np.abs((e - centre) @ np.array([-u[1], u[0]])).max(axis=1)
            fits = (np.abs(dn @ u) >= cos_max) & (off <= max_offset)
            grown = _grow(t, fits, group, max_gap, bridge, bridged)
            if np.array_equal(grown, group):
                break
            group = grown
        left[near[group]] = False
        centre, u = _line(e[group], ln[group])
        t = (e[group] - centre) @ u
        out.append(np.concatenate([centre + t.min() * u, centre + t.max() * u]))
    merged = np.asarray(out).reshape(-1, 4)
    # merged segments are better fitted than the fragments: merge them again until stable
    if len(merged) == len(seg):
        return merged
    return merge(merged, max_angle, max_offset, max_gap, solid, max_bridge)


def wall_test(image: np.ndarray, work: MetricGrid,
              level: float) -> Callable[[np.ndarray], np.ndarray]:
    """``solid(xy)``: whether points (..., 2), metres, fall on cells of ``image`` (on grid
    ``work``) of at least ``level``; points outside the image are not solid."""

    to_pixels = work.xy_to_pixel_matrix()
    rows, cols = image.shape

    def solid(xy: np.ndarray) -> np.ndarray:
        uv = np.floor(xy.reshape(-1, 2) @ to_pixels[:2, :2].T + to_pixels[:2, 2] + 0.5)
        uv = uv.astype(np.int64)
        inside = (uv[:, 0] >= 0) & (uv[:, 0] < cols) & (uv[:, 1] >= 0) & (uv[:, 1] < rows)
        out = np.zeros(len(uv), dtype=bool)
        out[inside] = image[uv[inside, 1], uv[inside, 0]] >= level
        return out.reshape(xy.shape[:-1])

    return solid


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
    dist, _ = cKDTree(_points(seg, step)[0]).query(xy, distance_upper_bound=distance)
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
