"""Pictures of a Result: the vectorial map per detector, and the map-to-truth distance heatmap.

Everything is drawn in the truth frame, axes in metres (matplotlib, headless Agg backend).

Rasters are drawn at display resolution: a grid with more cells across or down than its panel
has pixels at :data:`DPI` is max-pooled (:mod:`pcmapq.raster.pool`) to fit, so a map of any
size costs a picture of the same size (at most about 0.7 MP a vectorial panel, 1 MP the
heatmap), and a wall one cell thin still shows, which matplotlib's nearest resampling of a
larger image would skip (on a 2000-pixel raster of one-cell walls drawn into 600 pixels it
showed 4 walls of 50). A grid that fits is drawn cell for cell, as before.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.cm import ScalarMappable  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar  # noqa: E402

from pcmapq.morphology import distance_to  # noqa: E402
from pcmapq.raster.pool import max_pool, min_pool  # noqa: E402
from pcmapq.report.text import score  # noqa: E402
from pcmapq.result import DetectorResult, Result  # noqa: E402

TRUTH_GREY, MAP_BLUE = (0.62, 0.62, 0.62), (0.25, 0.55, 0.95)
MATCHED, MISSING, EXTRA, FOOTPRINT = "#1a9850", "#d73027", "#f28e2b", "#7b3294"
NICE = (1, 2, 5)
#: Dots per inch of the PNGs (:func:`png_bytes`' default); rasters are pooled to the pixels their
#: panel has at this resolution (saved at fewer dpi, matplotlib skips some of their rows again).
DPI = 130


def _nice(value: float) -> float:
    """The largest 1, 2 or 5 times a power of ten not above ``value``."""
    power = 10.0 ** np.floor(np.log10(value))
    return max(n * power for n in NICE if n * power <= value)


def extent(result: Result, factor: int = 1) -> tuple[float, float, float, float]:
    """(left, right, bottom, top), metres, of the truth grid's raster pooled ``factor``-fold: the
    grid's extent (yaw of the grid ignored), grown right and down by the part of the last
    column and row of blocks that lies past the grid (none at factor 1)."""
    x0, y0, _ = result.grid.origin
    rows, cols = result.grid.shape
    res = result.grid.resolution
    blocks_down, blocks_across = -(-rows // factor) * factor, -(-cols // factor) * factor
    return x0, x0 + blocks_across * res, y0 + (rows - blocks_down) * res, y0 + rows * res


def pooling(fig: Figure, axes: Sequence[Axes], shape: tuple[int, int]) -> int:
    """The smallest pooling factor that leaves a raster of ``shape`` (rows, cols) no more cells
    across and down than each of ``axes`` has pixels at :data:`DPI`, once ``fig`` is laid out
    (its titles, labels, legend and colour bar placed, the axes' aspect ratio applied). The
    axes are then put back where they were: the layout is run again when the figure is saved,
    and from where it starts depends where it ends, to a fraction of a pixel."""
    before = [(ax, ax.get_position(original=True), ax.get_in_layout()) for ax in fig.axes]
    fig.get_layout_engine().execute(fig)
    factor = 1
    for ax in axes:
        ax.apply_aspect()
        box = ax.get_position()
        across = box.width * fig.get_figwidth() * DPI
        down = box.height * fig.get_figheight() * DPI
        factor = max(factor, math.ceil(shape[0] / down), math.ceil(shape[1] / across))
    for ax, position, in_layout in before:
        ax.set_position(position)
        ax.set_in_layout(in_layout)  # which set_position turns off
    return factor


def _frame(ax: Axes, result: Result) -> None:
    """Axes in metres over the truth grid's extent, one metre as long across as down."""
    left, right, bottom, top = extent(result)
    ax.set_xlim(left, right)
    ax.set_ylim(bottom, top)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")


def overlay(truth: np.ndarray, map_: np.ndarray) -> np.ndarray:
    """RGB image (float) of two wall masks of one shape: white, the truth's walls grey, the
    aligned map's walls blue over them."""
    img = np.ones((*truth.shape, 3))
    img[truth] = TRUTH_GREY
    img[map_] = MAP_BLUE
    return img


def arrow_gain(result: Result) -> float:
    """How much displacement arrows are lengthened: a 1, 2 or 5 step chosen so that the
    largest displacement draws about 4 % of the map's width."""
    d = np.concatenate([det.distances for det in result.detectors.values()] + [np.zeros(1)])
    if d.max() <= 0:
        return 1.0
    return max(1.0, _nice(0.04 * result.grid.size_m[0] / d.max()))


def _title(ax: Axes, result: Result, name: str) -> None:
    m = result.detectors[name].matching
    ax.set_title(f"{name}: quality {score(m.quality, 2)}, precision {score(m.precision, 2)}, "
                 f"f1 {score(m.f1, 2)}"
                 + (f"\n{note}" if (note := result.note(name)) else ""), fontsize=10)


def _panel(ax: Axes, result: Result, factor: int, image: np.ndarray,
           footprint: np.ndarray | None, det: DetectorResult, gain: float) -> None:
    """One detector's panel over ``image`` and ``footprint``, the rasters pooled
    ``factor``-fold."""
    ax.imshow(image, extent=extent(result, factor), origin="upper", interpolation="nearest")
    if footprint is not None:
        ax.contour(footprint, levels=[0.5], colors=FOOTPRINT, linewidths=0.8,
                   extent=extent(result, factor), origin="upper")
    m = det.matching
    if det.truth.segments is not None:  # Hough: draw the segments themselves
        for idx, feats, colour in ((m.truth_idx, det.truth, MATCHED),
                                   (m.missing, det.truth, MISSING), (m.extra, det.map, EXTRA)):
            ax.add_collection(LineCollection(feats.segments[idx].reshape(-1, 2, 2),
                                             colors=colour, linewidths=1.6))
    ax.scatter(*det.truth_xy.T, s=9, c=MATCHED, zorder=3)
    ax.scatter(*det.truth.xy[m.missing].T, s=28, c=MISSING, marker="x", zorder=3)
    ax.scatter(*det.map.xy[m.extra].T, s=28, c=EXTRA, marker="+", zorder=3)
    if len(m.displacement):
        q = ax.quiver(*det.truth_xy.T, *m.displacement.T, angles="xy", scale_units="xy",
                      scale=1.0 / gain, color="black", width=0.003, zorder=4)
        ref = _nice(max(float(det.distances.max()), 1e-3))
        ax.quiverkey(q, 0.04, 0.04, ref, f"{ref:g} m (x{gain:g})", labelpos="E",
                     coordinates="axes", fontproperties={"size": 8})
    width = result.grid.size_m[0]
    bar = _nice(width / 5)
    ax.add_artist(AnchoredSizeBar(ax.transData, bar, f"{bar:g} m", "lower right", pad=0.4,
                                  frameon=True, size_vertical=width / 300))


def vectorial_figure(result: Result) -> Figure:
    """One panel per detector: truth grey, aligned map blue, matched features with their
    displacement arrows, missing truth features and extra map features, the footprint outline."""
    names = list(result.detectors)
    width, height = result.grid.size_m
    cols = len(names)
    panel_w = 6.0
    panel_h = float(np.clip(panel_w * height / max(width, 1e-9), 3.0, 9.0))
    fig, axes = plt.subplots(1, cols, figsize=(panel_w * cols, panel_h + 1.2), squeeze=False,
                             layout="constrained")
    gain = arrow_gain(result)
    handles = [Line2D([], [], color=TRUTH_GREY, lw=4, label="truth walls"),
               Line2D([], [], color=MAP_BLUE, lw=4, label="aligned map walls"),
               Line2D([], [], color=MATCHED, marker="o", ls="", label="matched (truth)"),
               Line2D([], [], color="black", marker=r"$\rightarrow$", ls="", ms=12,
                      label=f"displacement to the map (x{gain:g})"),
               Line2D([], [], color=MISSING, marker="x", ls="", label="missing in the map"),
               Line2D([], [], color=EXTRA, marker="+", ls="", label="extra in the map")]
    if not result.full:
        handles.append(Line2D([], [], color=FOOTPRINT, lw=1, label="map footprint"))
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8,
               frameon=False)
    for ax, name in zip(axes[0], names, strict=True):
        _title(ax, result, name)
        _frame(ax, result)
    factor = pooling(fig, axes[0], result.grid.shape)
    image = overlay(max_pool(result.truth_occupied, factor), max_pool(result.map_occupied, factor))
    footprint = None if result.full else max_pool(result.overlap.footprint, factor)
    for ax, name in zip(axes[0], names, strict=True):
        _panel(ax, result, factor, image, footprint, result.detectors[name], gain)
    return fig


def wall_distances(truth: np.ndarray, map_: np.ndarray, resolution: float,
                   factor: int) -> np.ndarray:
    """Per block of ``factor`` x ``factor`` cells, the smallest distance, metres, from the map's
    wall cells in it to the nearest truth wall cell: truth, map_ (rows, cols) bool wall masks
    of cells of ``resolution`` metres -> (ceil(rows / factor), ceil(cols / factor)) float64,
    NaN where the block holds no map wall.

    The distances are the full grid's (a float32 transform, 4 bytes a cell), so each shown value
    is one the accuracy statistics count; a transform on the pooled truth would be cheaper but
    off by up to a pooled cell's diagonal (24 mm on the Gazebo truth, pooled 9-fold; 1 to 1.5 s
    and 0.3 GB saved there). The smallest, because a block's
    distance to the truth is that of its nearest wall cell, as a cell's is; the block's other
    wall cells are at most its diagonal farther.
    """
    cells = distance_to(truth)
    np.copyto(cells, np.float32(np.nan), where=~map_)
    return np.multiply(min_pool(cells, factor), resolution, dtype=np.float64)


def distance_heatmap(result: Result, clip: float = 0.5) -> Figure:
    """Each occupied cell of the aligned map coloured by its distance to the nearest truth wall,
    metres (clipped at ``clip``); the truth's walls in grey beneath. Pooled to display
    resolution (:func:`wall_distances`)."""
    width, height = result.grid.size_m
    fig, ax = plt.subplots(figsize=(8.0, float(np.clip(8.0 * height / width, 3.0, 10.0))),
                           layout="constrained")
    colours = ScalarMappable(Normalize(0, clip), "viridis")
    fig.colorbar(colours, ax=ax, label=f"map-to-truth distance [m] (clipped at {clip:g})",
                 shrink=0.8)
    ax.set_title("distance from each map wall cell to the nearest truth wall", fontsize=10)
    _frame(ax, result)
    factor = pooling(fig, [ax], result.grid.shape)
    truth = max_pool(result.truth_occupied, factor)
    base = np.ones((*truth.shape, 3))
    base[truth] = (0.82, 0.82, 0.82)
    ax.imshow(base, extent=extent(result, factor), origin="upper", interpolation="nearest")
    shown = wall_distances(result.truth_occupied, result.map_occupied, result.grid.resolution,
                           factor)
    ax.imshow(np.minimum(shown, clip), extent=extent(result, factor), origin="upper",
              cmap=colours.cmap, norm=colours.norm, interpolation="nearest")
    return fig


def png_bytes(fig: Figure, dpi: int = DPI) -> bytes:
    """The figure as PNG bytes (then closed)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()
