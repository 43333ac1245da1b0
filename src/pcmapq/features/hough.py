"""Hough wall segments, in metres.

Detection: the walls' image (see :mod:`pcmapq.features.walls`) is smoothed with a Gaussian of
``sigma`` metres and thinned to its ridge lines (pixels that are the maximum of the smoothed
image across the ridge, given by the Hessian), so a filled plan wall, a wall seen as two laser
faces and a wall seen as one face all give one centre line (:mod:`pcmapq.features.ridges`).
Segments come from two sources:

- ridge pieces: connected runs of ridge pixels whose local direction (from the Hessian) stays
  within one 30 degree bin, fitted by their principal axis (two bin partitions, half a bin
  apart). A piece follows the ridge pixels themselves, so a real wall that is wavy by a pixel
  or two stays one straight piece, and a piece never jumps between parallel walls or cuts
  across a curve. At least ``support * min_length`` long.
- probabilistic Hough (``cv2.HoughLinesP``, rho = one working cell) on the ridge lines, where
  the pieces leave a wall out: segments at least ``min_length`` long, cut where they leave the
  wall (smoothed image below ``inside``), and kept only when no piece passes within
  ``merge_offset`` of their midpoint. So a Hough line may span a ridge that is broken or
  rounded inside a wall (the ring-shaped centre line of a small box) but never open floor, and
  it never adds a second, differently cut copy of a wall the pieces already hold.

Hough alone, on the one-pixel ridges of a real SLAM map (walls one or two cells thin, wavy,
broken), gives fragments, chords across curves and jumps between nearby walls that change with
every re-rasterisation; the pieces do not. Pieces and
segments are then merged into maximal wall segments, so one straight wall (between doors) is one
feature. ``xy`` is the segment midpoint, ``strength`` its length in
metres; strong segments are at least ``min_length`` long, support-level ones at least
``support * min_length``.

Matching rule: a truth segment and a map segment are candidates when their directions differ
by less than ``max_angle`` (10) degrees, the map segment projected on the truth segment's line
overlaps the truth segment, and the perpendicular offset, the larger of the two
midpoint-to-other-line distances, is within the threshold; the cost is that offset divided by
the threshold. The
displacement is the vector from the truth midpoint to its orthogonal projection on the map
segment's line: a wall moved by 0.5 m shows 0.5 m, whatever the segments' extents.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from pcmapq.features.base import (
    Candidates,
    Detector,
    Features,
    by_strips,
    empty_features,
    gaussian_reach,
    no_candidates,
    sorted_features,
)
from pcmapq.features.merging import merge
from pcmapq.features.ridges import pieces, ridges
from pcmapq.features.segments import away, directions, inside_runs, near_pairs, wall_test
from pcmapq.features.walls import WallImage


@dataclass(frozen=True)
class Params:
    """Parameters of the Hough wall segment detector and of its matching rule.

    sigma: smoothing scale of the ridge (centre line) detection, metres.
    ridge: least scale-normalised ridge strength; a one-cell (0.05 m) line scores about 0.2.
    min_length: length of a strong segment, metres.
    max_gap: largest gap bridged inside one segment, metres.
    support: support-level segments are at least ``support * min_length`` long.
    angle_step: Hough theta step, degrees (rho is one working cell).
    merge_angle, merge_offset: collinear fragments within this angle (degrees) and
        perpendicular offset (metres) are merged when at most ``max_gap`` apart along the line,
        or at most ``max_bridge`` (metres) apart with the wall solid all along the gap: this
        joins a wall across the break of its centre line at a T junction, but not across a
        door.
    max_bridge: see ``merge_angle``, metres.
    inside: smoothed occupied fraction a Hough segment keeps all along; it is cut where it
        drops below.
    solid: smoothed occupied fraction above which a cell is inside a wall, for bridging.
    max_angle: largest direction difference of matching segments, degrees.
    """

    sigma: float = 0.1
    ridge: float = 0.05
    min_length: float = 0.5
    max_gap: float = 0.2
    support: float = 0.5
    angle_step: float = 0.5
    merge_angle: float = 15.0
    merge_offset: float = 0.15
    max_bridge: float = 1.5
    inside: float = 0.5
    solid: float = 0.3
    max_angle: float = 10.0


def detect(walls: WallImage, params: Params) -> Features:
    """Maximal wall segments of a binary map, seen as ``walls`` (see
    :func:`pcmapq.features.walls.wall_image`), in the metric frame of its grid, whose cell is
    also the Hough rho step: ``segments`` (N, 4), ``xy`` their midpoints and ``strength`` their
    lengths, metres."""
    p, image, work = params, walls.image, walls.grid
    resolution = work.resolution
    sigma_px = p.sigma / resolution
    # the blur's reach, its derivatives' pixel and one more
    mask, direction, smooth = by_strips(image, gaussian_reach(sigma_px) + 2,
                                        lambda strip: ridges(strip, sigma_px, p.ridge))
    shortest = p.support * p.min_length
    px = pieces(mask, direction)
    _, size = directions(px)
    parts = [work.pixels_to_xy(px[size >= shortest / resolution].reshape(-1, 2)).reshape(-1, 4)]
    lines = cv2.HoughLinesP(mask.astype(np.uint8) * 255, 1.0, np.radians(p.angle_step),
                            max(2, int(0.8 * p.min_length / resolution)),
                            minLineLength=p.min_length / resolution,
                            maxLineGap=p.max_gap / resolution)
    if lines is not None:
        hough = work.pixels_to_xy(lines.reshape(-1, 2).astype(np.float64)).reshape(-1, 4)
        hough = inside_runs(hough, wall_test(smooth, work, p.inside), 0.5 * resolution,
                            p.min_length)
        # only where no piece is: never a second, differently cut copy of a wall
        mid = 0.5 * (hough[:, :2] + hough[:, 2:])
        parts.append(hough[away(mid, parts[0], p.merge_offset, 0.5 * resolution)])
    seg = np.concatenate(parts)
    if len(seg) == 0:
        return empty_features(with_segments=True)
    solid = wall_test(smooth, work, p.solid)
    seg = merge(seg, p.merge_angle, p.merge_offset, p.max_gap, solid, p.max_bridge)
    _, length = directions(seg)
    seg, length = seg[length >= shortest], length[length >= shortest]
    # canonical endpoint order: the lexicographically smaller endpoint first
    flip = (seg[:, 0] > seg[:, 2]) | ((seg[:, 0] == seg[:, 2]) & (seg[:, 1] > seg[:, 3]))
    seg[flip] = seg[flip][:, [2, 3, 0, 1]]
    mid = 0.5 * (seg[:, :2] + seg[:, 2:])
    return sorted_features(mid, length, length >= p.min_length, segments=seg)


def candidates(truth: Features, map_: Features, threshold: float, params: Params) -> Candidates:
    """Candidate segment pairs under the rule of the module docstring (directions within
    ``params.max_angle`` degrees); cost = offset / threshold."""
    if len(truth) == 0 or len(map_) == 0:
        return no_candidates()
    dt, lt = directions(truth.segments)
    dm, _ = directions(map_.segments)
    # a candidate pair comes within threshold / cos(max_angle) of each other (the map segment
    # where it meets the end of the truth segment's extent, or its midpoint), so only such
    # pairs are tested
    cos_max = np.cos(np.radians(params.max_angle))
    i, j = near_pairs(truth.segments, map_.segments, threshold / max(cos_max, 1e-3))
    parallel = np.abs(np.einsum("ij,ij->i", dt[i], dm[j])) >= cos_max
    i, j = i[parallel], j[parallel]
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


DETECTOR = Detector("hough", detect, candidates, Params)
