"""What every picture of a result shares: the part of the truth frame it shows and its axes in
metres, the pooling that brings a raster to display resolution, the shaded rasters (walls, or a
3D cloud's density) and the thinning of markers. Truth frame, metres.

A picture shows the cells that hold walls of either side, their features and the map's
footprint, with a margin, not the whole truth grid: a building drawn in the middle of a large
plan image fills its panels as a map of its own size does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import cv2
import numpy as np

from pcmapq.core.bounds import nonzero_window
from pcmapq.raster.pool import max_pool, mean_pool
from pcmapq.report.style import DPI, MAP_LIGHT, TEXT_PT, TRUTH_DARK
from pcmapq.results.result import Result

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Shade of a pixel with any occupied cell in a density picture (so a lone hit shows), and
#: of the truth over the map.
DENSITY_FLOOR, TRUTH_ALPHA = 0.3, 0.9
#: Margin around what a picture shows: this share of its box's larger side, at least
#: MARGIN_MIN_M metres.
MARGIN, MARGIN_MIN_M = 0.05, 1.0

#: Rows and columns of the truth grid (row 0 at the top), as slices.
Window = tuple[slice, slice]


def window(result: Result) -> Window:
    """The rows and columns of the truth grid a picture shows: the box of the cells that hold
    walls of either side (and the map's footprint, unless scored against the whole truth) and
    of every feature of either side, grown by :data:`MARGIN` and cut to the grid; the whole
    grid when there is none."""
    shown = result.truth_occupied | result.map_occupied
    if not result.full:
        shown = shown | result.overlap.footprint
    boxes = [box] if (box := nonzero_window(shown)) is not None else []
    xy = [f.xy for d in result.detectors.values() for f in (d.truth, d.map) if len(f.xy)]
    if xy:
        u, v = result.grid.xy_to_pixels(np.vstack(xy)).T
        boxes.append((math.floor(v.min() + 0.5), math.floor(v.max() + 0.5) + 1,
                      math.floor(u.min() + 0.5), math.floor(u.max() + 0.5) + 1))
    rows, cols = result.grid.shape
    if not boxes:
        return slice(0, rows), slice(0, cols)
    lo, hi = min(b[0] for b in boxes), max(b[1] for b in boxes)
    left, right = min(b[2] for b in boxes), max(b[3] for b in boxes)
    margin = max(math.ceil(MARGIN * max(hi - lo, right - left)),
                 math.ceil(MARGIN_MIN_M / result.grid.resolution))
    return (slice(min(rows - 1, max(0, lo - margin)), max(1, min(rows, hi + margin))),
            slice(min(cols - 1, max(0, left - margin)), max(1, min(cols, right + margin))))


def size_m(result: Result, shown: Window) -> tuple[float, float]:
    """(width, height), metres, of the ``shown`` window of the truth grid."""
    rows, cols = shown
    res = result.grid.resolution
    return (cols.stop - cols.start) * res, (rows.stop - rows.start) * res


def extent(result: Result, factor: int = 1,
           shown: Window | None = None) -> tuple[float, float, float, float]:
    """(left, right, bottom, top), metres, of the truth grid's raster, or of its ``shown``
    window (:func:`window`), pooled ``factor``-fold: its extent (yaw of the grid ignored),
    grown right and down by the part of the last column and row of blocks that lies past it
    (none at factor 1)."""
    x0, y0, _ = result.grid.origin
    rows, cols = result.grid.shape
    r, c = shown or (slice(0, rows), slice(0, cols))
    res = result.grid.resolution
    blocks_down = -(-(r.stop - r.start) // factor) * factor
    blocks_across = -(-(c.stop - c.start) // factor) * factor
    left, top = x0 + c.start * res, y0 + (rows - r.start) * res
    return left, left + blocks_across * res, top - blocks_down * res, top


def pooling(fig: Figure, axes: Sequence[Axes], shape: tuple[int, int]) -> tuple[int, float]:
    """The smallest pooling factor that leaves a raster of ``shape`` (rows, cols) no more cells
    across and down than each of ``axes`` has pixels at :data:`DPI`, once ``fig`` is laid out
    (its titles, labels, legend and colour bar placed, the axes' aspect ratio applied), and the
    metres a pixel spans in the smallest of them. The axes are then put back where they were:
    the layout is run again when the figure is saved, and from where it starts depends where
    it ends, to a fraction of a pixel."""
    before = [(ax, ax.get_position(original=True), ax.get_in_layout()) for ax in fig.axes]
    fig.get_layout_engine().execute(fig)
    factor, pixel_m = 1, 0.0
    for ax in axes:
        ax.apply_aspect()
        box = ax.get_position()
        across = box.width * fig.get_figwidth() * DPI
        down = box.height * fig.get_figheight() * DPI
        factor = max(factor, math.ceil(shape[0] / down), math.ceil(shape[1] / across))
        pixel_m = max(pixel_m, abs(np.diff(ax.get_xlim())[0]) / across)
    for ax, position, in_layout in before:
        ax.set_position(position)
        ax.set_in_layout(in_layout)  # which set_position turns off
    return factor, pixel_m


def frame(ax: Axes, result: Result, shown: Window | None = None) -> None:
    """Axes in metres over the truth grid's extent, or its ``shown`` window, one metre as long
    across as down."""
    left, right, bottom, top = extent(result, 1, shown)
    ax.set_xlim(left, right)
    ax.set_ylim(bottom, top)
    ax.set_xlabel("x [m]", fontsize=TEXT_PT)
    ax.set_ylabel("y [m]", fontsize=TEXT_PT)
    ax.tick_params(labelsize=TEXT_PT)
    ax.set_aspect("equal")


def density(result: Result) -> bool:
    """Whether ``result``'s pictures show densities (both inputs 3D clouds: LiDAR maps) rather
    than walls."""
    return result.registration_3d is not None


def shade(mask: np.ndarray, factor: int, as_density: bool) -> np.ndarray:
    """Opacity per display pixel of a (rows, cols) bool mask pooled ``factor``-fold, [0, 1]:
    1 where a block holds a true cell (walls), or the blocks' occupied share, square-rooted and
    lifted to at least DENSITY_FLOOR where not 0 (density)."""
    if not as_density:
        return max_pool(mask, factor).astype(np.float64)
    share = mean_pool(mask, factor)
    return np.where(share > 0, DENSITY_FLOOR + (1 - DENSITY_FLOOR) * np.sqrt(share), 0.0)


def grown(alpha: np.ndarray) -> np.ndarray:
    """``alpha`` (rows, cols) float with each pixel taking its 3 x 3 neighbourhood's largest
    value: drawn one pixel wider on every side."""
    return cv2.dilate(alpha.astype(np.float32), np.ones((3, 3), np.uint8),
                      borderType=cv2.BORDER_REPLICATE).astype(np.float64)


def overlay(truth_alpha: np.ndarray, map_alpha: np.ndarray) -> np.ndarray:
    """RGB image (float) of two opacities of one shape on white: the aligned map light
    (MAP_LIGHT), the truth dark (TRUTH_DARK) over it at TRUTH_ALPHA of its opacity."""
    img = np.ones((*truth_alpha.shape, 3))
    for colour, alpha in ((MAP_LIGHT, map_alpha), (TRUTH_DARK, TRUTH_ALPHA * truth_alpha)):
        img += alpha[..., None] * (np.asarray(colour) - img)
    return img


def thinned(xy: np.ndarray, cell_m: float) -> np.ndarray:
    """Indices (sorted) of the first of ``xy`` (N, 2) metres in each square of ``cell_m``
    metres: at most one point a square."""
    if len(xy) == 0:
        return np.zeros(0, dtype=np.intp)
    _, first = np.unique(np.floor(xy / cell_m).astype(np.int64), axis=0, return_index=True)
    return np.sort(first)
