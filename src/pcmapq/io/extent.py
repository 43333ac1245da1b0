"""An input's extent in metres: its plan points, a crop to a box (``--map-crop``,
``--truth-crop``), and why an absurd extent looks wrong (points far from the rest, another
unit, a resolution that is not in metres per cell).

Boxes are ``(x0, y0, x1, y1)``, metres, in the input's own frame (x and y of a cloud; the
map_server frame of an image).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from pcmapq.core.bounds import Box, bounds
from pcmapq.core.cells import OCCUPIED, UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.core.words import plural
from pcmapq.io.clouds import PointMap
from pcmapq.io.occupancy import OccupancyMap

#: An input wider than this, metres, is refused: no map scored on a grid of centimetres spans it.
MAX_SPAN = 100_000.0
#: Points summarised by :func:`hint` (a stride through larger inputs).
SAMPLE = 200_000
#: Gaps are looked for between occupied bins of this width, metres.
BIN = 1.0
#: A gap at least this wide, metres, and wider than the main group, splits groups.
MIN_GAP = 50.0
#: Spans above this, metres, suggest another unit (millimetres).
UNIT_SPAN = 2000.0
#: Cell sizes outside this range, metres, suggest a resolution that is not metres per cell.
SANE_RESOLUTION = (1e-3, 10.0)


def plan_sample(source: OccupancyMap | PointMap, size: int = SAMPLE) -> np.ndarray:
    """At most about ``size`` of the input's plan points, (N, 2) metres, in its own frame: the
    occupied cell centres of an image, x and y of a cloud (every k-th row)."""
    if isinstance(source, OccupancyMap):
        v, u = np.nonzero(source.state == OCCUPIED)
        step = max(1, len(v) // size)
        return source.grid.pixels_to_xy(np.column_stack([u[::step], v[::step]]))
    step = max(1, len(source.points) // size)
    return np.asarray(source.points[::step, :2], dtype=np.float64)


def span(source: OccupancyMap | PointMap) -> tuple[float, float]:
    """Width and height of the input, metres: the image's size, the box of a cloud's x, y."""
    if isinstance(source, OccupancyMap):
        return source.grid.size_m
    lo, hi = bounds(source.points[:, :2])
    with np.errstate(over="ignore"):
        return float(hi[0]) - float(lo[0]), float(hi[1]) - float(lo[1])


def main_group(xy: np.ndarray) -> Box | None:
    """Where most points ``xy`` (N, 2, metres) lie when the rest are far away: the box of the
    largest group (split at gaps of at least :data:`MIN_GAP` metres and wider than the group,
    along x, then the points kept split along y), grown by :data:`BIN` and rounded outwards to
    0.1 m; None when the points form one group."""
    keep = np.ones(len(xy), dtype=bool)
    for axis in (0, 1):
        kept = np.flatnonzero(keep)  # y splits what x kept: the two never keep disjoint sets
        bins = np.floor(xy[kept, axis] / BIN)
        edges = np.unique(bins)
        gap = np.diff(edges) * BIN
        cuts = np.flatnonzero(gap >= MIN_GAP)
        if len(cuts) == 0:
            continue
        group = np.searchsorted(edges[cuts + 1], bins, side="right")
        largest = np.argmax(np.bincount(group))
        lo, hi = np.concatenate([edges[:1], edges[cuts + 1]]), np.append(edges[cuts], edges[-1])
        width = (hi[largest] - lo[largest] + 1) * BIN
        near = np.concatenate([gap[cuts][largest - 1:largest], gap[cuts][largest:largest + 1]])
        if near.max() > width:
            keep[kept[group != largest]] = False
    if keep.all():
        return None
    inside = xy[keep]
    lo, hi = bounds(inside)
    (x0, y0), (x1, y1) = np.floor((lo - BIN) * 10) / 10, np.ceil((hi + BIN) * 10) / 10
    return float(x0), float(y0), float(x1), float(y1)


def _box_text(box: Box) -> str:
    """``x0,y0,x1,y1`` to 0.1 m (to 6 digits beyond a million kilometres)."""
    return ",".join(f"{value:.1f}" if abs(value) < 1e9 else f"{value:.6g}" for value in box)


def _count(source: OccupancyMap | PointMap) -> int:
    """Points of a cloud, occupied cells of an image."""
    if isinstance(source, OccupancyMap):
        return int(np.count_nonzero(source.state == OCCUPIED))
    return len(source.points)


def outside(source: OccupancyMap | PointMap, box: Box) -> int:
    """How many of a cloud's points (an image's occupied cells) lie outside ``box``."""
    if isinstance(source, PointMap):
        return int(np.count_nonzero(~_inside(source.points, box)))
    return _count(source) - _count(crop(source, box, ""))


def _inside(points: np.ndarray, box: Box) -> np.ndarray:
    """(N,) bool: the points (N, 2+, metres) whose x, y lie in ``box``."""
    x0, y0, x1, y1 = box
    x, y = points[:, 0], points[:, 1]
    return (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)


def far_points(source: OccupancyMap | PointMap, option: str) -> str:
    """When most of an input lies in one place and the rest far from it (see
    :func:`main_group`): one clause that says so and gives the ``option`` (``--map-crop`` or
    ``--truth-crop``) that keeps the main part; else empty."""
    xy = plan_sample(source)
    xy = xy[np.isfinite(xy).all(axis=1)]
    box = main_group(xy) if len(xy) else None
    if box is None:
        return ""
    width, height = span(source)
    far = outside(source, box)
    verb = "lies" if far == 1 else "lie"
    total = _count(source)
    return (f"{far:,} of its {total:,} {plural(total, 'point')} {verb} far from the others, "
            "which lie "
            f"within {_box_text(box)} ({box[2] - box[0]:.0f} x {box[3] - box[1]:.0f} m; it "
            f"spans {width:.3g} x {height:.3g} m): outliers, or two maps in one file? "
            f"{option} {_box_text(box)} keeps that part")


def hint(source: OccupancyMap | PointMap, option: str, cell: float | None = None) -> str:
    """What looks wrong with an input too large to score, and how to fix it, one clause: a cell
    size (an image's, or ``cell`` metres, the grid drawn for a cloud) that is not metres per
    cell, points far from the rest (:func:`far_points`), or a span that suggests another unit.
    ``option`` is the crop option of its side. Empty when nothing looks wrong."""
    width, height = span(source)
    cell = source.grid.resolution if isinstance(source, OccupancyMap) else cell
    if cell is not None and not SANE_RESOLUTION[0] <= cell <= SANE_RESOLUTION[1]:
        return (f"its cells are {cell:g} m wide ({width:.3g} x {height:.3g} m in all): "
                "resolutions are metres per cell")
    far = far_points(source, option)
    if far:
        return far
    if max(width, height) > UNIT_SPAN:
        return (f"it spans {width:.3g} x {height:.3g} m: are its coordinates in millimetres or "
                f"another unit? pcmapq reads metres ({option} keeps a part)")
    return ""


def check_span(source: OccupancyMap | PointMap, option: str) -> None:
    """InputError (one line) for an input wider than :data:`MAX_SPAN` metres, saying why."""
    width, height = span(source)
    if max(width, height) <= MAX_SPAN:
        return
    why = hint(source, option) or f"it spans {width:.3g} x {height:.3g} m"
    raise InputError(f"{source.path}: wider than {MAX_SPAN / 1000:.0f} km, too wide to score: "
                     f"{why}")


def crop(source: OccupancyMap | PointMap, box: Box, option: str) -> OccupancyMap | PointMap:
    """The part of the input inside ``box`` (metres, its own frame): a cloud's points with x, y
    inside; an image's cells whose centres lie inside (the image cut to them, cells of the cut
    outside the box made unknown). InputError when nothing is left."""
    x0, y0, x1, y1 = box
    if isinstance(source, PointMap):
        inside = _inside(source.points, box)
        if not inside.any():
            raise InputError(f"{source.path}: {option} {_box_text(box)} keeps none of its points")
        return replace(source, points=np.ascontiguousarray(source.points[inside],
                                                           dtype=np.float64),
                       scan=None if source.scan is None else np.asarray(source.scan)[inside])
    grid = source.grid
    corners = grid.xy_to_pixels(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]))
    rows, cols = grid.shape
    u0, v0 = np.maximum(np.ceil(corners.min(axis=0)), 0).astype(int)
    u1, v1 = np.minimum(np.floor(corners.max(axis=0)), [cols - 1, rows - 1]).astype(int)
    if u0 > u1 or v0 > v1:
        raise InputError(f"{source.path}: {option} {_box_text(box)} keeps none of its cells")
    state = source.state[v0:v1 + 1, u0:u1 + 1].copy()
    x, y = grid.pixels_to_xy(np.array([[u0 - 0.5, v1 + 0.5]]))[0]
    cut = MetricGrid(grid.resolution, (float(x), float(y), grid.origin[2]), state.shape)
    if grid.origin[2] != 0.0:  # a turned image: its cut holds cells outside the box
        centres = cut.cell_centres(np.ones(state.shape, dtype=bool)).reshape(*state.shape, 2)
        state[(centres[..., 0] < x0) | (centres[..., 0] > x1) | (centres[..., 1] < y0)
              | (centres[..., 1] > y1)] = UNKNOWN
    return replace(source, grid=cut, state=state)
