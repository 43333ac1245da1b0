"""Hough wall segments, in metres.

Detection: the working image (see :mod:`pcmapq.features.base`) is smoothed with a Gaussian of
``sigma`` metres and thinned to its ridge lines (pixels that are the maximum of the smoothed
image across the ridge, given by the Hessian), so a filled plan wall, a wall seen as two laser
faces and a wall seen as one face all give one centre line. Segments come from two sources:

- ridge pieces: connected runs of ridge pixels whose local direction (from the Hessian) stays
  within one 30 degree bin, fitted by their principal axis (two bin partitions, half a bin
  apart). A piece follows the ridge pixels themselves, so a real wall that is wavy by a pixel
  or two stays one straight piece, and a piece never jumps between parallel walls or cuts
  across a curve. At least ``support * min_length`` long.
- probabilistic Hough (``cv2.HoughLinesP``, rho = one working cell) on the ridge lines, where
  the pieces leave a wall out: segments at least ``min_length`` long, cut where they leave the
  wall (smoothed image below ``_INSIDE``), and kept only when no piece passes within
  ``merge_offset`` of their midpoint. So a Hough line may span a ridge that is broken or
  rounded inside a wall (the ring-shaped centre line of a small box) but never open floor, and
  it never adds a second, differently cut copy of a wall the pieces already hold.

Hough alone, on the one-pixel ridges of a real SLAM map (walls one or two cells thin, wavy,
broken), gave fragments, chords across curves and jumps between nearby walls that changed with
every re-rasterisation (a turned Freiburg 079 map scored 0.63); the pieces do not. Pieces and
segments are then merged into maximal wall segments, so one straight wall (between doors) is one
feature. ``xy`` is the segment midpoint, ``strength`` its length in
metres; strong segments are at least ``min_length`` long, support-level ones at least
``support * min_length``.

Matching rule: a truth segment and a map segment are candidates when their directions differ
by less than ``MAX_ANGLE`` (10) degrees, the map segment projected on the truth segment's line
overlaps the truth segment, and the perpendicular offset, the larger of the two
midpoint-to-other-line distances, is within the threshold; the cost is that offset divided by
the threshold. The
displacement is the vector from the truth midpoint to its orthogonal projection on the map
segment's line: a wall moved by 0.5 m shows 0.5 m, whatever the segments' extents.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np
from scipy.spatial import cKDTree

from pcmapq.features.base import (
    Candidates,
    Detector,
    Features,
    empty_features,
    gaussian,
    no_candidates,
    sorted_features,
)
from pcmapq.features.walls import WallImage
from pcmapq.grid import MetricGrid

#: Largest direction difference of matching segments, degrees.
MAX_ANGLE = 10.0


def ridges(image: np.ndarray, sigma_px: float, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """One-pixel centre lines of the bright ridges of ``image`` (Steger's detector), and their
    local direction.

    A pixel is on a ridge when the maximum of the smoothed image across the ridge (along the
    Hessian's most negative eigenvector, to second order) lies inside the pixel: the line is
    one pixel wide wherever the wall's centre falls between pixels. Blob-like points (curved as
    much along as across, i.e. wall ends) are left out, so the lines stop short of wall ends
    and T junctions instead of fanning out.

    Parameters
    ----------
    image : (rows, cols) float32 in [0, 1].
    sigma_px : smoothing scale, pixels.
    floor : least ridge strength ``-sigma^2 * lambda`` (scale-normalised second derivative
        across the ridge), dimensionless.

    Returns
    -------
    mask : (rows, cols) bool mask of ridge pixels.
    direction : (rows, cols) float32 direction along the ridge, radians in [0, pi) measured
        from the pixel u axis towards v (meaningful on the mask only).
    """
    s = gaussian(image, sigma_px)

    def diff(du: int, dv: int, scale: float) -> np.ndarray:
        return cv2.Sobel(s, cv2.CV_32F, du, dv, ksize=3, borderType=cv2.BORDER_REFLECT) / scale

    gu, gv = diff(1, 0, 8.0), diff(0, 1, 8.0)
    a, c, b = diff(2, 0, 4.0), diff(0, 2, 4.0), diff(1, 1, 4.0)
    root = np.sqrt(0.25 * (a - c) ** 2 + b * b)
    lam, along = 0.5 * (a + c) - root, 0.5 * (a + c) + root  # across and along the ridge
    theta = 0.5 * np.arctan2(2 * b, a - c) + 0.5 * np.pi  # eigenvector of lam: across
    nu, nv = np.cos(theta), np.sin(theta)
    t = -(gu * nu + gv * nv) / np.minimum(lam, -1e-12)  # distance to the maximum, pixels
    inside = (np.abs(t * nu) <= 0.5) & (np.abs(t * nv) <= 0.5)
    line_like = np.abs(along) <= 0.5 * np.abs(lam)  # not a blob (a wall end)
    mask = inside & line_like & (-lam * sigma_px**2 >= floor)
    return mask, np.mod(theta + 0.5 * np.pi, np.pi).astype(np.float32)


#: Direction bins of one partition of the ridge pixels (30 degrees each).
_BINS = 6


def _label(mask: np.ndarray, direction: np.ndarray, offset: float) -> tuple[np.ndarray, int]:
    """Connected pieces (8-connected) of ridge pixels whose directions fall in the same bin of
    ``_BINS`` bins over [0, pi), the bins shifted by ``offset`` of a bin: (rows, cols) int32
    labels (0 off the pieces) and the number of pieces."""
    bins = np.floor(np.mod(direction * (_BINS / np.pi) + offset, _BINS)).astype(np.int32)
    labels = np.zeros(mask.shape, dtype=np.int32)
    count = 0
    for k in range(_BINS):
        n, lab = cv2.connectedComponents((mask & (bins == k)).astype(np.uint8), connectivity=8)
        on = lab > 0
        labels[on] = lab[on] + count
        count += n - 1
    return labels, count


def pieces(mask: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Straight pieces of the ridge lines, in pixels (u, v): (N, 4) ``u0, v0, u1, v1``.

    The ridge pixels are split by their local direction into 30 degree bins; each connected run
    of pixels of one bin is a piece, fitted by the principal axis of its pixels and spanning
    them (to the outer edges of its end pixels). Two partitions, the second shifted by half a
    bin, are used together, so a wall whose direction lies on a bin border is still whole in one
    of them; the duplicates are merged later. A piece follows the ridge pixels themselves: it
    neither jumps between parallel walls nor cuts across a curve, and a wall wavy by a pixel
    stays one piece as long as its direction stays within the bin.
    """
    out = []
    for offset in (0.0, 0.5):
        labels, n = _label(mask, direction, offset)
        v, u = np.nonzero(labels)
        lab = labels[v, u]
        count = np.bincount(lab, minlength=n + 1).astype(np.float64)
        count[0] = 1.0
        cu = np.bincount(lab, u, n + 1) / count
        cv = np.bincount(lab, v, n + 1) / count
        du, dv = u - cu[lab], v - cv[lab]
        suu = np.bincount(lab, du * du, n + 1)
        svv = np.bincount(lab, dv * dv, n + 1)
        suv = np.bincount(lab, du * dv, n + 1)
        angle = 0.5 * np.arctan2(2 * suv, suu - svv)  # principal axis of each piece
        eu, ev = np.cos(angle), np.sin(angle)
        t = du * eu[lab] + dv * ev[lab]
        lo, hi = np.full(n + 1, np.inf), np.full(n + 1, -np.inf)
        np.minimum.at(lo, lab, t)
        np.maximum.at(hi, lab, t)
        lo, hi = lo[1:] - 0.5, hi[1:] + 0.5  # pixel centres to pixel edges
        cu, cv, eu, ev = cu[1:], cv[1:], eu[1:], ev[1:]
        out.append(np.column_stack([cu + lo * eu, cv + lo * ev, cu + hi * eu, cv + hi * ev]))
    return np.concatenate(out).reshape(-1, 4)


def _directions(seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions (N, 2) and lengths (N,) of segments (N, 4)."""
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    return d / np.maximum(length, 1e-12)[:, None], length


#: Regroup-and-refit rounds of one merged segment.
_REFITS = 4
#: Smoothed occupied fraction above which a cell is inside a wall, for bridging.
_SOLID = 0.3
#: Points tested along a gap to bridge.
_BRIDGE_SAMPLES = 16
#: Smoothed occupied fraction a Hough segment keeps all along; it is cut where it drops below.
_INSIDE = 0.5


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
          bridged: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
    """The group extended by every fitting segment near its extent along the line, repeatedly,
    as the extent grows.

    ``t`` (N, 2) are the endpoint positions along the line, metres. A segment is near when the
    gap between it and the group is at most ``max_gap``, or when ``bridged(start, end)`` says
    the wall is solid over the gap (positions along the line, metres, one pair per segment).
    """
    a, b = t.min(axis=1), t.max(axis=1)
    while True:
        lo, hi = t[group].min(), t[group].max()
        above = a > hi
        start, end = np.where(above, hi, b), np.where(above, a, lo)
        gap = np.where(above | (b < lo), end - start, 0.0)
        near = fits & ~group & (gap <= max_gap)
        far = np.flatnonzero(fits & ~group & ~near)
        if len(far):
            near[far] = bridged(start[far], end[far])
        if not near.any():
            return group
        group = group | near


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
    d, length = _directions(seg)
    ends = np.stack([seg[:, :2], seg[:, 2:]], axis=1)  # (N, 2, 2)
    cos_max = np.cos(np.radians(max_angle))
    cos_near = np.cos(np.radians(min(2 * max_angle, 90.0)))
    steps = np.linspace(0.0, 1.0, _BRIDGE_SAMPLES)
    left = np.ones(len(seg), dtype=bool)
    out = []
    for seed in np.lexsort((seg[:, 1], seg[:, 0], -length)):  # longest first
        if not left[seed]:
            continue
        # the group's line stays near its seed's: only fragments within twice the angle and
        # offset of the seed's line can join (this keeps the loop cheap on large maps)
        u = d[seed]
        off = np.abs((ends - ends[seed, 0]) @ np.array([-u[1], u[0]])).max(axis=1)
        near = np.flatnonzero(left & (np.abs(d @ u) >= cos_near) & (off <= 2 * max_offset))
        e, dn, ln = ends[near], d[near], length[near]
        group = near == seed
        for _ in range(_REFITS):
            centre, u = _line(e[group], ln[group])

            def bridged(start: np.ndarray, end: np.ndarray, centre=centre, u=u) -> np.ndarray:
                if solid is None:
                    return np.zeros(len(start), dtype=bool)
                pos = start[:, None] + (end - start)[:, None] * steps  # (K, S) along the line
                return (end - start <= max_bridge) & solid(centre + pos[..., None] * u).all(1)

            t = (e - centre) @ u  # (K, 2) along the line
            off = np.abs((e - centre) @ np.array([-u[1], u[0]])).max(axis=1)
            fits = (np.abs(dn @ u) >= cos_max) & (off <= max_offset)
            grown = _grow(t, fits, group, max_gap, bridged)
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

    def solid(xy: np.ndarray) -> np.ndarray:
        uv = np.floor(work.xy_to_pixels(xy.reshape(-1, 2)) + 0.5).astype(np.int64)
        rows, cols = image.shape
        inside = (uv[:, 0] >= 0) & (uv[:, 0] < cols) & (uv[:, 1] >= 0) & (uv[:, 1] < rows)
        out = np.zeros(len(uv), dtype=bool)
        out[inside] = image[uv[inside, 1], uv[inside, 0]] >= level
        return out.reshape(xy.shape[:-1])

    return solid


def _points(seg: np.ndarray, step: float) -> np.ndarray:
    """Points (M, 2) every ``step`` along segments (N, 4), both ends included."""
    d, length = _directions(seg)
    n = np.floor(length / step).astype(np.int64) + 2
    which = np.repeat(np.arange(len(seg)), n)
    t = np.minimum((np.arange(n.sum()) - (np.cumsum(n) - n)[which]) * step, length[which])
    return seg[which, :2] + t[:, None] * d[which]


def away(xy: np.ndarray, seg: np.ndarray, distance: float, step: float) -> np.ndarray:
    """(N,) bool: which points ``xy`` (N, 2) are farther than ``distance`` from every segment
    (M, 4) (tested at points every ``step`` along them). Metres."""
    if len(seg) == 0 or len(xy) == 0:
        return np.ones(len(xy), dtype=bool)
    dist, _ = cKDTree(_points(seg, step)).query(xy, distance_upper_bound=distance)
    return ~np.isfinite(dist)


def inside_runs(seg: np.ndarray, inside: Callable[[np.ndarray], np.ndarray], step: float,
                shortest: float) -> np.ndarray:
    """The parts of segments (N, 4, metres) along which ``inside(xy)`` holds at every point
    tested (every ``step`` metres), at least ``shortest`` metres long: (M, 4) metres."""
    d, length = _directions(seg)
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


def detect(walls: WallImage, *, sigma: float = 0.1, ridge: float = 0.05, min_length: float = 0.5,
           max_gap: float = 0.2, support: float = 0.5, angle_step: float = 0.5,
           merge_angle: float = 15.0, merge_offset: float = 0.15,
           max_bridge: float = 1.5) -> Features:
    """Maximal wall segments of a binary map.

    Parameters
    ----------
    walls : the walls as detectors see them (:func:`pcmapq.features.walls.wall_image`);
        segments are returned in the metric frame of its grid, whose cell is also the Hough
        rho step.
    sigma : smoothing scale of the ridge (centre line) detection, metres.
    ridge : least scale-normalised ridge strength; a one-cell (0.05 m) line scores about 0.2.
    min_length : length of a strong segment, metres.
    max_gap : largest gap bridged inside one segment, metres.
    support : support-level segments are at least ``support * min_length`` long.
    angle_step : Hough theta step, degrees.
    merge_angle, merge_offset : collinear fragments within this angle (degrees) and
        perpendicular offset (metres) are merged when at most ``max_gap`` apart along the line,
        or at most ``max_bridge`` (metres) apart with the wall solid all along the gap: this
        joins a wall across the break of its centre line at a T junction, but not across a
        door.

    Returns
    -------
    Features with ``segments`` (N, 4), ``xy`` the midpoints and ``strength`` the lengths.
    """
    image, work = walls.image, walls.grid
    resolution = work.resolution
    mask, direction = ridges(image, sigma / resolution, ridge)
    smooth = gaussian(image, sigma / resolution)
    shortest = support * min_length
    px = pieces(mask, direction)
    _, size = _directions(px)
    parts = [work.pixels_to_xy(px[size >= shortest / resolution].reshape(-1, 2)).reshape(-1, 4)]
    lines = cv2.HoughLinesP(mask.astype(np.uint8) * 255, 1.0, np.radians(angle_step),
                            max(2, int(0.8 * min_length / resolution)),
                            minLineLength=min_length / resolution, maxLineGap=max_gap / resolution)
    if lines is not None:
        hough = work.pixels_to_xy(lines.reshape(-1, 2).astype(np.float64)).reshape(-1, 4)
        hough = inside_runs(hough, wall_test(smooth, work, _INSIDE), 0.5 * resolution, min_length)
        # only where no piece is: never a second, differently cut copy of a wall
        mid = 0.5 * (hough[:, :2] + hough[:, 2:])
        parts.append(hough[away(mid, parts[0], merge_offset, 0.5 * resolution)])
    seg = np.concatenate(parts)
    if len(seg) == 0:
        return empty_features(with_segments=True)
    solid = wall_test(smooth, work, _SOLID)
    seg = merge(seg, merge_angle, merge_offset, max_gap, solid, max_bridge)
    _, length = _directions(seg)
    seg = seg[length >= support * min_length]
    length = length[length >= support * min_length]
    # canonical endpoint order: the lexicographically smaller endpoint first
    flip = (seg[:, 0] > seg[:, 2]) | ((seg[:, 0] == seg[:, 2]) & (seg[:, 1] > seg[:, 3]))
    seg[flip] = seg[flip][:, [2, 3, 0, 1]]
    mid = 0.5 * (seg[:, :2] + seg[:, 2:])
    return sorted_features(mid, length, length >= min_length, segments=seg)


def candidates(truth: Features, map_: Features, threshold: float) -> Candidates:
    """Candidate segment pairs under the rule of the module docstring; cost = offset /
    threshold."""
    if len(truth) == 0 or len(map_) == 0:
        return no_candidates()
    dt, lt = _directions(truth.segments)
    dm, _ = _directions(map_.segments)
    i, j = np.nonzero(np.abs(dt @ dm.T) >= np.cos(np.radians(MAX_ANGLE)))
    either = truth.strong[i] | map_.strong[j]
    i, j = i[either], j[either]
    mt, mm = truth.xy[i], map_.xy[j]
    nt = np.column_stack([-dt[i, 1], dt[i, 0]])
    nm = np.column_stack([-dm[j, 1], dm[j, 0]])
    along_m = np.einsum("ij,ij->i", mm - mt, nm)  # truth midpoint to map line, signed
    cost = np.maximum(np.abs(along_m), np.abs(np.einsum("ij,ij->i", mm - mt, nt)))
    # the map segment's endpoints on the truth line, truth segment from -L/2 to L/2
    a = np.einsum("ij,ij->i", map_.segments[j, :2] - mt, dt[i])
    b = np.einsum("ij,ij->i", map_.segments[j, 2:] - mt, dt[i])
    overlap = np.minimum(np.maximum(a, b), 0.5 * lt[i]) - np.maximum(np.minimum(a, b), -0.5 * lt[i])
    keep = (overlap > 0) & (cost <= threshold)
    disp = along_m[keep, None] * nm[keep]
    return i[keep], j[keep], cost[keep] / threshold, disp


DETECTOR = Detector("hough", detect, candidates)
