"""The footprint of a map: the part of the truth's grid that the map observed.

Rules (``--footprint``, documented in docs/method.md):
- ``known``: an occupancy image observed its known cells, free or occupied, drawn into the
  truth's grid;
- ``walls``: the map observed the area its walls enclose: its occupied cells, closed with a disc
  of radius ``close`` metres (bridging doors and gaps between walls) and with holes filled; a
  room whose walls were seen is observed, open ground beyond the outermost walls is not. A
  point cloud's rule, and a binary image's (black walls on white: no unknown value, so no
  evidence of what was not observed);
- ``seen``: a map made of scans with known poses (``pcmapq track``'s maps) observed the free
  space its scans swept: the union of their views, each the outline from the scanner through
  its readings in angular order (a beam with no return cuts the view back to the scanner), so
  a room the robot looked into is observed and one behind a wall it never passed is not. The
  map's cells outside it (readings that drew no wall, see :func:`joined_readings`) are not
  added to it, and their features are not counted (``evaluation.scoring.score``);
- ``all``: the map's whole rectangle (an image's extent, a cloud's bounding box, in its frame);
- ``auto`` (default): ``known`` for an image with unknown regions, ``seen`` for a map with
  views, ``walls`` otherwise. An
  unknown region is what remains of the unknown cells after an opening by a disc of
  ``UNKNOWN_WIDTH`` metres (so anti-aliased wall edges, a thin grey border, stray pixels do not
  count); an image has them when they make up at least ``UNKNOWN_SHARE`` of it.
Whatever the rule, the footprint (with the map's occupied cells, but for ``seen``) is then
grown by ``margin`` metres, so truth features on the border of what the map saw (a wall the
map ends on) count as inside.
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy import ndimage

from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import disc, distance_to
from pcmapq.raster.draw import polygon_cells
from pcmapq.raster.rules import FOOTPRINT_RULES

#: Unknown cells count as an unknown region when they are part of a patch at least this wide,
#: metres: an opening by a disc of this diameter.
UNKNOWN_WIDTH = 0.5
#: An image whose unknown regions make up at least this share of it has ``known`` cells that
#: say what it observed (``auto``); below it, it is treated as binary (``walls``).
UNKNOWN_SHARE = 0.01


def enclosed_area(occupied: np.ndarray, grid: MetricGrid, close: float = 1.5) -> np.ndarray:
    """Cells enclosed by the occupied cells (bool, same grid): closing by a disc of radius
    ``close`` metres, then hole filling. Done on a grid of at least 0.1 m cells for speed."""
    step = max(1, int(np.floor(0.1 / grid.resolution)))
    small = occupied
    if step > 1:
        rows, cols = occupied.shape
        pad = np.pad(occupied, ((0, -rows % step), (0, -cols % step)))
        small = pad.reshape(pad.shape[0] // step, step, pad.shape[1] // step, step).any(axis=(1, 3))
    # pad so the closing does not stick to the border of the grid
    kernel = disc(close / (grid.resolution * step))
    r = kernel.shape[0]
    padded = np.pad(small.astype(np.uint8), r)
    closed = cv2.morphologyEx(padded, cv2.MORPH_CLOSE, kernel)
    filled = ndimage.binary_fill_holes(closed[r:-r, r:-r])
    if step > 1:
        filled = np.repeat(np.repeat(filled, step, axis=0), step, axis=1)
        filled = filled[: occupied.shape[0], : occupied.shape[1]]
    return filled | occupied


def grow(area: np.ndarray, grid: MetricGrid, margin: float) -> np.ndarray:
    """``area`` grown by ``margin`` metres (bool, same grid): the cells within
    ``max(1, round(margin / resolution))`` cells of it. An exact Euclidean distance transform,
    so the time does not depend on the margin (a dilation by a disc of r cells costs about r
    times more, which a wide margin on a fine grid makes prohibitive)."""
    if margin <= 0 or not area.any():
        return area
    radius = max(1, int(round(margin / grid.resolution)))
    return distance_to(area) <= radius


def unknown_regions(unknown: np.ndarray, resolution: float,
                    width: float = UNKNOWN_WIDTH) -> np.ndarray:
    """The unknown cells (bool) that belong to a patch at least ``width`` metres wide: an
    opening by a disc of that diameter (two exact distance transforms). Beyond the image is
    known, so a thin unknown border is not a region. ``resolution``: metres per cell."""
    r = width / 2.0 / resolution  # cells
    pad = int(np.ceil(r)) + 1
    padded = np.pad(unknown.astype(bool), pad)
    core = distance_to(~padded) > r
    opened = distance_to(core) <= r
    return (opened & padded)[pad:-pad, pad:-pad]


def footprint_rule(requested: str, unknown: np.ndarray | None, resolution: float,
                   views: bool = False) -> str:
    """The rule a map's footprint follows: ``requested`` (one of FOOTPRINT_RULES), with
    ``auto`` resolved. ``unknown``: the image's unknown cells (None for a point cloud);
    ``resolution``: the image's metres per cell; ``views``: the cloud has its scans' views.
    Raises ValueError for ``known`` on a cloud, ``seen`` without views."""
    check_rule(requested, unknown is not None, views)
    if unknown is None:
        return ("seen" if views else "walls") if requested == "auto" else requested
    if requested != "auto":
        return requested
    if not unknown.any():
        return "walls"
    share = float(unknown_regions(unknown, resolution).mean())
    return "known" if share >= UNKNOWN_SHARE else "walls"


def check_rule(requested: str, image: bool, views: bool = False) -> None:
    """ValueError (one line) when a map cannot follow the footprint rule ``requested``:
    :func:`footprint_rule`'s refusals, found without resolving ``auto``."""
    if requested not in FOOTPRINT_RULES:
        raise ValueError(f"unknown footprint rule {requested!r}; choose from "
                         f"{', '.join(FOOTPRINT_RULES)}")
    if requested == "seen" and not views:
        raise ValueError("footprint 'seen' needs the scans' poses (a map that 'pcmapq track' "
                         "builds): 'walls' or 'all'")
    if not image and requested == "known":
        raise ValueError("a point cloud has no known cells: footprint 'walls' or 'all'")


def map_footprint(rule: str, occupied: np.ndarray, grid: MetricGrid, margin: float,
                  known: np.ndarray | None = None,
                  rectangle: np.ndarray | None = None,
                  seen: np.ndarray | None = None) -> np.ndarray:
    """The map's footprint on the truth's grid (bool) under ``rule`` (resolved: ``known``,
    ``walls``, ``seen`` or ``all``, see :func:`footprint_rule`): its known cells, the area its
    occupied cells enclose, the cells its scans saw (``seen``, bool, see
    :func:`pcmapq.raster.seen.seen_on`) or its rectangle (``rectangle``: (4, 2) corners,
    truth frame, metres), with the ``occupied`` cells (but for ``seen``: the readings that drew
    no wall stay out); grown by ``margin`` metres."""
    if rule == "known" and known is not None:
        area = known
    elif rule == "seen" and seen is not None:
        area = seen
    elif rule == "all" and rectangle is not None:
        area = polygon_cells(rectangle, grid)
    elif rule == "walls":
        area = enclosed_area(occupied, grid)
    else:
        raise ValueError(f"footprint rule {rule!r} needs what this map lacks")
    return grow(area if rule == "seen" else area | occupied, grid, margin)


def joined_readings(points: np.ndarray, scan: np.ndarray, gap: float) -> np.ndarray:
    """(N,) bool: the readings that draw a wall as a line: those whose neighbours on both
    sides, the readings before and after them in the same scan, lie within ``gap`` metres.
    ``points`` (N, 2, metres) are the readings of each scan in beam order, ``scan`` (N,) the
    scan of each. A wall far away or seen at a grazing angle is a row of dots instead (1-degree
    beams land 0.2 m apart at 11.5 m facing the wall, farther apart along it)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    scan = np.asarray(scan)
    near = np.zeros(len(points) + 1, bool)  # near[i]: readings i - 1 and i are joined
    near[1:-1] = (scan[1:] == scan[:-1]) & (np.hypot(*np.diff(points, axis=0).T) <= gap)
    return near[:-1] & near[1:]


def view_outlines(origins: np.ndarray, points: np.ndarray, scan: np.ndarray,
                  bins: int = 360) -> np.ndarray:
    """The views of K scans, (K, bins, 2) metres: scan k's farthest reading in each of
    ``bins`` equal angular sectors around its scanner at ``origins[k]`` (K, 2), in angular
    order, or the scanner itself for a sector with no reading. ``points`` (N, 2) are the
    readings in the same frame, ``scan`` (N,) the scan of each. A star-shaped polygon: the
    free space the scan saw (:func:`pcmapq.raster.seen.add_views` fills it)."""
    origins = np.asarray(origins, dtype=np.float64).reshape(-1, 2)
    offset = np.asarray(points, dtype=np.float64).reshape(-1, 2) - origins[scan]
    angle = np.arctan2(offset[:, 1], offset[:, 0])
    sector = np.minimum(((angle + np.pi) / (2 * np.pi) * bins).astype(np.int64), bins - 1)
    reach = np.zeros((len(origins), bins))
    np.maximum.at(reach, (scan, sector), np.hypot(offset[:, 0], offset[:, 1]))
    centre = -np.pi + (np.arange(bins) + 0.5) * (2 * np.pi / bins)
    return origins[:, None, :] + reach[..., None] * np.stack([np.cos(centre),
                                                               np.sin(centre)], axis=-1)
