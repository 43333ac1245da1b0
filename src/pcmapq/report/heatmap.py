"""The distance heatmaps of a Result: accuracy (each wall cell of the aligned map coloured by
its distance to the nearest truth wall) and completeness (each truth wall cell the scores
count, by its distance to the nearest map wall), in the truth frame, metres, pooled to
display resolution as every picture is (:mod:`pcmapq.report.plot`)."""

from __future__ import annotations

import cv2
import numpy as np
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from pcmapq.core.morphology import distance_to
from pcmapq.raster.pool import max_pool, min_pool
from pcmapq.report.canvas import extent, frame, pooling, size_m, window
from pcmapq.report.plot import plt  # Agg backend
from pcmapq.report.style import TEXT_PT, TITLE_PT, WIDTH_IN
from pcmapq.results.result import Result

#: Grey of the walls under a heatmap's coloured cells.
UNDER_GREY = (0.8, 0.8, 0.8)


def wall_distances(target: np.ndarray, source: np.ndarray, resolution: float,
                   factor: int) -> np.ndarray:
    """Per block of ``factor`` x ``factor`` cells, the smallest distance, metres, from the
    ``source`` wall cells in it to the nearest ``target`` wall cell: target, source (rows, cols)
    bool wall masks of cells of ``resolution`` metres -> (ceil(rows / factor),
    ceil(cols / factor)) float64, NaN where the block holds no source wall. Accuracy: the
    map's walls to the truth's; completeness: the truth's to the map's.

    The distances are the full grid's (a float32 transform, 4 bytes a cell), so each shown value
    is one the statistics count; a transform on the pooled target would be cheaper but off by
    up to a pooled cell's diagonal. The smallest, because a block's distance to the target is
    that of its nearest wall cell, as a cell's is; the block's other wall cells are at most its
    diagonal farther.
    """
    cells = distance_to(target)
    np.copyto(cells, np.float32(np.nan), where=~source)
    return np.multiply(min_pool(cells, factor), resolution, dtype=np.float64)


def _heat_panel(ax: Axes, box: tuple[float, float, float, float], under: np.ndarray,
                shown: np.ndarray, colours: ScalarMappable, title: str) -> None:
    """``under`` (pooled bool) in grey, then ``shown`` (pooled distances, NaN where none)
    coloured by ``colours``, each coloured pixel grown by one pixel so lone cells show; both
    over the ``box`` (left, right, bottom, top; metres)."""
    base = np.ones((*under.shape, 3))
    base[under] = UNDER_GREY
    ax.imshow(base, extent=box, origin="upper", interpolation="nearest")
    near = -cv2.dilate(np.nan_to_num(-shown, nan=-np.inf).astype(np.float32),
                       np.ones((3, 3), np.uint8), borderType=cv2.BORDER_REPLICATE)
    ax.imshow(np.where(np.isfinite(near), np.minimum(near, colours.norm.vmax), np.nan),
              extent=box, origin="upper", cmap=colours.cmap,
              norm=colours.norm, interpolation="nearest")
    ax.set_title(title, fontsize=TITLE_PT)


def distance_heatmap(result: Result, clip: float = 0.5) -> Figure:
    """Two panels: accuracy (each occupied cell of the aligned map coloured by its distance to
    the nearest truth wall, the truth's walls grey beneath) and completeness (each truth wall
    cell the scores count, inside the footprint unless scored against the whole truth,
    coloured by its distance to the nearest map wall, the map's walls grey beneath); metres,
    clipped at ``clip``. Pooled to display resolution (:func:`wall_distances`); over the part
    of the truth grid that holds walls (:func:`~pcmapq.report.canvas.window`)."""
    shown = window(result)
    res = result.grid.resolution
    width, height = size_m(result, shown)
    panel_w = WIDTH_IN / 2
    fig, axes = plt.subplots(1, 2, figsize=(WIDTH_IN, float(np.clip(
        panel_w * height / width, 2.5, 9.0)) + 1.4), layout="constrained")
    colours = ScalarMappable(Normalize(0, clip), "viridis")
    bar = fig.colorbar(colours, ax=list(axes), location="bottom", shrink=0.6, aspect=40)
    bar.set_label(f"distance to the nearest wall of the other side [m] (clipped at {clip:g})",
                  fontsize=TEXT_PT)
    bar.ax.tick_params(labelsize=TEXT_PT)
    for ax in axes:
        frame(ax, result, shown)
    # every wall of both sides lies in the window, so its distances are the whole grid's
    truth, walls = result.truth_occupied[shown], result.map_occupied[shown]
    factor, _ = pooling(fig, list(axes), truth.shape)
    box = extent(result, factor, shown)
    counted = truth if result.full else truth & result.overlap.footprint[shown]
    _heat_panel(axes[0], box, max_pool(truth, factor),
                wall_distances(truth, walls, res, factor), colours,
                "accuracy: map walls to the truth")
    _heat_panel(axes[1], box, max_pool(walls, factor),
                wall_distances(walls, counted, res, factor), colours,
                "completeness: truth walls to the map")
    return fig
