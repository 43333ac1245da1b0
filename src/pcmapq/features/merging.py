"""Collinear wall fragments merged into maximal segments (the Hough detector's last step).
Segments are (N, 4) ``x0, y0, x1, y1`` in metres.

The merge is greedy and sequential (each group takes its fragments out of the pool), so its
loop is compiled by Numba (on first use, cached on disk) and runs without holding Python's
lock: ``pcmapq track`` merges two steps' fragments at once.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pcmapq.core.bounds import bounds
from pcmapq.features.segments import WallTest, directions

#: Regroup-and-refit rounds of one merged segment.
REFITS = 4
#: Points tested along a gap to bridge.
BRIDGE_SAMPLES = 16
#: Tiles a side of the index of the segments' midpoints.
TILES = 64


def merge(seg: np.ndarray, max_angle: float, max_offset: float, max_gap: float,
          solid: WallTest | None = None, max_bridge: float = 0.0) -> np.ndarray:
    """Merge collinear fragments into maximal segments.

    Longest first, each remaining segment seeds a group that absorbs every fragment within
    ``max_angle`` of the group's line direction, ``max_offset`` of the line and ``max_gap`` of
    its extent along it (or up to ``max_bridge`` away when the wall is solid all along the gap);
    the line is then refitted to the group (weighted total least squares of the endpoints) and
    the group regathered, a few rounds. Fragments are compared with the group's line, not with
    each other, so a chain of slightly turning fragments cannot drift. Only fragments within
    twice ``max_angle`` and twice ``max_offset`` of the seed's line are considered (the group's
    line stays near its seed's; an index of the midpoints keeps large maps fast). The merged
    segments are merged again until nothing changes.

    Parameters
    ----------
    seg : (N, 4) segments, metres.
    max_angle : largest direction difference, degrees.
    max_offset : largest distance of a fragment's endpoints from the group's line, metres.
    max_gap : largest gap along the line between the group's extent and a fragment, metres.
    solid : which points are inside a wall (:func:`~pcmapq.features.segments.wall_test`);
        None: none.
    max_bridge : largest gap bridged where ``solid`` holds all along it, metres.

    Returns
    -------
    (M, 4) merged segments: each group's fitted line, spanning all of its endpoints. Metres,
    M <= N.
    """
    seg = np.ascontiguousarray(seg, dtype=np.float64).reshape(-1, 4)
    if solid is None:  # no gap is bridged without a wall test
        image, to_pixels, level, bridge = np.zeros((1, 1)), np.eye(3), np.inf, -np.inf
    else:
        image, to_pixels, level, bridge = solid.image, solid.to_pixels, solid.level, max_bridge
    limits = np.array([np.cos(np.radians(max_angle)),
                       np.cos(np.radians(min(2 * max_angle, 90.0))),
                       max_offset, max_gap, bridge])
    steps = np.linspace(0.0, 1.0, BRIDGE_SAMPLES)
    while len(seg):
        d, length = directions(seg)
        seeds = np.lexsort((seg[:, 1], seg[:, 0], -length))  # longest first
        merged = _merge_pass(seg, d, length, seeds, *_tiles(seg), limits, steps,
                             np.ascontiguousarray(image), np.asarray(to_pixels, np.float64),
                             float(level))
        # merged segments are better fitted than the fragments: merge them again until stable
        if len(merged) == len(seg):
            return merged
        seg = merged
    return seg


def _tiles(seg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """The segments bucketed by the square tile (of :data:`TILES` a side) holding their
    midpoint: the segments in tile order, each filled tile's first position in it and count,
    its centre (F, 2, metres), and the tile's side, metres."""
    mid = 0.5 * (seg[:, :2] + seg[:, 2:])
    lo, hi = bounds(mid)
    size = max(float((hi - lo).max()) / TILES, 1e-9)
    cell = np.floor((mid - lo) / size).astype(np.int64)
    shape = bounds(cell)[1] + 1
    tile = cell[:, 0] * shape[1] + cell[:, 1]
    order = np.argsort(tile, kind="stable")
    counts = np.bincount(tile, minlength=int(np.prod(shape)))
    filled = np.flatnonzero(counts)
    ix, iy = np.divmod(filled, shape[1])
    centres = lo + (np.column_stack([ix, iy]) + 0.5) * size
    return order, (np.cumsum(counts) - counts)[filled], counts[filled], centres, size


@numba.njit(cache=True, nogil=True)
def _near_line(px: float, py: float, nx: float, ny: float, width: float, order: np.ndarray,
               starts: np.ndarray, counts: np.ndarray, centres: np.ndarray,
               size: float) -> np.ndarray:
    """Sorted indices of every segment whose midpoint may lie within ``width`` metres of the
    line through (px, py) with unit normal (nx, ny) (and of some beyond it)."""
    reach = width + size / math.sqrt(2.0)  # a midpoint is this near its tile's centre
    found = np.empty(len(order), np.int64)
    k = 0
    for f in range(len(starts)):
        if abs((centres[f, 0] - px) * nx + (centres[f, 1] - py) * ny) <= reach:
            for m in range(starts[f], starts[f] + counts[f]):
                found[k] = order[m]
                k += 1
    return np.sort(found[:k])


@numba.njit(cache=True, nogil=True)
def _line(seg: np.ndarray, near: np.ndarray, group: np.ndarray,
          length: np.ndarray) -> tuple[float, float, float, float]:
    """Weighted total-least-squares line through the endpoints of the segments ``near[group]``,
    each weighted by its length: a point on it and its unit direction."""
    total, sx, sy = 0.0, 0.0, 0.0
    for k in range(len(near)):
        if group[k]:
            c, w = near[k], length[near[k]]
            sx += w * seg[c, 0] + w * seg[c, 2]
            sy += w * seg[c, 1] + w * seg[c, 3]
            total += 2.0 * w
    cx, cy = sx / total, sy / total
    cxx, cxy, cyy = 0.0, 0.0, 0.0
    for k in range(len(near)):
        if group[k]:
            c, w = near[k], length[near[k]]
            for e in (0, 2):
                rx, ry = seg[c, e] - cx, seg[c, e + 1] - cy
                cxx += w * rx * rx
                cxy += w * rx * ry
                cyy += w * ry * ry
    angle = 0.5 * math.atan2(2.0 * cxy, cxx - cyy)  # principal axis
    return cx, cy, math.cos(angle), math.sin(angle)


@numba.njit(cache=True, nogil=True)
def _solid_along(cx: float, cy: float, ux: float, uy: float, start: float, end: float,
                 steps: np.ndarray, image: np.ndarray, to_pixels: np.ndarray,
                 level: float) -> bool:
    """Whether every point tested between positions ``start`` and ``end`` along the line
    through (cx, cy) with direction (ux, uy) falls on a wall cell (as :class:`WallTest`)."""
    rows, cols = image.shape
    for s in steps:
        pos = start + (end - start) * s
        x, y = cx + pos * ux, cy + pos * uy
        u = int(np.floor(x * to_pixels[0, 0] + y * to_pixels[0, 1] + to_pixels[0, 2] + 0.5))
        v = int(np.floor(x * to_pixels[1, 0] + y * to_pixels[1, 1] + to_pixels[1, 2] + 0.5))
        if u < 0 or u >= cols or v < 0 or v >= rows or not image[v, u] >= level:
            return False
    return True


@numba.njit(cache=True, nogil=True)
def _grow(a: np.ndarray, b: np.ndarray, fits: np.ndarray, group: np.ndarray, max_gap: float,
          bridge: float, line: tuple[float, float, float, float], steps: np.ndarray,
          image: np.ndarray, to_pixels: np.ndarray, level: float) -> np.ndarray:
    """The group extended by every fitting segment near its extent along the line, repeatedly,
    as the extent grows. ``a``, ``b`` (K,): each segment's lower and upper endpoint position
    along the line, metres. A segment is near when the gap between it and the group is at most
    ``max_gap``, or at most ``bridge`` when the wall is solid over the gap."""
    group = group.copy()
    while True:
        lo, hi = np.inf, -np.inf
        for k in range(len(group)):
            if group[k]:
                lo, hi = min(lo, a[k]), max(hi, b[k])
        joined = group.copy()
        for k in range(len(group)):
            if group[k] or not fits[k]:
                continue
            if a[k] > hi:
                start, end = hi, a[k]
            elif b[k] < lo:
                start, end = b[k], lo
            else:
                start, end = 0.0, 0.0
            gap = end - start
            if gap <= max_gap or (gap <= bridge and _solid_along(
                    line[0], line[1], line[2], line[3], start, end, steps, image, to_pixels,
                    level)):
                joined[k] = True
        if (joined == group).all():
            return group
        group = joined


@numba.njit(cache=True, nogil=True)
def _merge_pass(seg: np.ndarray, d: np.ndarray, length: np.ndarray, seeds: np.ndarray,
                order: np.ndarray, starts: np.ndarray, counts: np.ndarray,
                centres: np.ndarray, size: float, limits: np.ndarray, steps: np.ndarray,
                image: np.ndarray, to_pixels: np.ndarray, level: float) -> np.ndarray:
    """One pass of :func:`merge` over ``seg`` (N, 4; unit directions ``d``, lengths
    ``length``), seeding groups in the order ``seeds``; the tiles of :func:`_tiles`;
    ``limits``: cos of the largest angle, cos of twice it, the largest offset, gap and bridge.
    The merged segments (M, 4)."""
    cos_max, cos_near, max_offset = limits[0], limits[1], limits[2]
    max_gap, bridge = limits[3], limits[4]
    left = np.ones(len(seg), np.bool_)
    out = np.empty((len(seg), 4))
    m = 0
    for seed in seeds:
        if not left[seed]:
            continue
        # the group's line stays near its seed's: only fragments within twice the angle and
        # offset of the seed's line can join
        ux, uy = d[seed, 0], d[seed, 1]
        px, py = seg[seed, 0], seg[seed, 1]
        found = _near_line(px, py, -uy, ux, 2 * max_offset, order, starts, counts, centres,
                           size)
        near = np.empty(len(found), np.int64)
        k = 0
        for c in found:
            off = max(abs((seg[c, 0] - px) * -uy + (seg[c, 1] - py) * ux),
                      abs((seg[c, 2] - px) * -uy + (seg[c, 3] - py) * ux))
            if left[c] and abs(d[c, 0] * ux + d[c, 1] * uy) >= cos_near \
                    and off <= 2 * max_offset:
                near[k] = c
                k += 1
        near = near[:k]
        group = near == seed
        a, b = np.empty(k), np.empty(k)
        fits = np.empty(k, np.bool_)
        for _ in range(REFITS if k > 1 else 0):  # a lone seed is its own group
            line = _line(seg, near, group, length)
            cx, cy, ux, uy = line
            for j in range(k):
                c = near[j]
                t0 = (seg[c, 0] - cx) * ux + (seg[c, 1] - cy) * uy
                t1 = (seg[c, 2] - cx) * ux + (seg[c, 3] - cy) * uy
                a[j], b[j] = min(t0, t1), max(t0, t1)
                off = max(abs((seg[c, 0] - cx) * -uy + (seg[c, 1] - cy) * ux),
                          abs((seg[c, 2] - cx) * -uy + (seg[c, 3] - cy) * ux))
                fits[j] = abs(d[c, 0] * ux + d[c, 1] * uy) >= cos_max and off <= max_offset
            grown = _grow(a, b, fits, group, max_gap, bridge, line, steps, image, to_pixels,
                          level)
            if (grown == group).all():
                break
            group = grown
        cx, cy, ux, uy = _line(seg, near, group, length)
        lo, hi = np.inf, -np.inf
        for j in range(k):
            if group[j]:
                left[near[j]] = False
                for e in (0, 2):
                    t = (seg[near[j], e] - cx) * ux + (seg[near[j], e + 1] - cy) * uy
                    lo, hi = min(lo, t), max(hi, t)
        out[m, 0], out[m, 1] = cx + lo * ux, cy + lo * uy
        out[m, 2], out[m, 3] = cx + hi * ux, cy + hi * uy
        m += 1
    return out[:m]
