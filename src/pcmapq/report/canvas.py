"""What every picture of a result shares: the truth frame's extent and axes in metres, the
pooling that brings a raster to display resolution, the shaded rasters (walls, or a 3D cloud's
density) and the thinning of markers. Truth frame, metres."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import cv2
import numpy as np

from pcmapq.raster.pool import max_pool, mean_pool
from pcmapq.report.style import DPI, MAP_LIGHT, TEXT_PT, TRUTH_DARK
from pcmapq.results.result import Result

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Shade of a pixel with any occupied cell in a density picture (so a lone hit shows), and
#: of the truth over the map.
DENSITY_FLOOR, TRUTH_ALPHA = 0.3, 0.9


def extent(result: Result, factor: int = 1) -> tuple[float, float, float, float]:
    """(left, right, bottom, top), metres, of the truth grid's raster pooled ``factor``-fold: the
    grid's extent (yaw of the grid ignored), grown right and down by the part of the last
    column and row of blocks that lies past the grid (none at factor 1)."""
    x0, y0, _ = result.grid.origin
    rows, cols = result.grid.shape
    res = result.grid.resolution
    blocks_down, blocks_across = -(-rows // factor) * factor, -(-cols // factor) * factor
    return x0, x0 + blocks_across * res, y0 + (rows - blocks_down) * res, y0 + rows * res


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


def frame(ax: Axes, result: Result) -> None:
    """Axes in metres over the truth grid's extent, one metre as long across as down."""
    left, right, bottom, top = extent(result)
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
