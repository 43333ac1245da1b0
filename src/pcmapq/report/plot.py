"""Pictures of a Result: the vectorial map per detector and the figure files (what every
picture shares is :mod:`pcmapq.report.canvas`; the rooms over a panel,
:mod:`pcmapq.report.rooms_layer`; the distance heatmaps, :mod:`pcmapq.report.heatmap`).

Everything is drawn in the truth frame, axes in metres (matplotlib, headless Agg backend). The
truth's walls are drawn dark over the aligned map's, light and one pixel wider, so both show
where they meet; every arrow goes from the truth to where the map has it (the map's error), at
one scale in every panel of a figure (:mod:`pcmapq.report.arrows`), stated in the legend;
legends and scale bars stand outside the axes, never over data; a figure is at most as wide as
the HTML report shows it (style.py).

Rasters are drawn at display resolution: a grid with more cells across or down than its panel
has pixels at :data:`DPI` is pooled (:mod:`pcmapq.raster.pool`) to fit, so a map of any size
costs a picture of the same size, and a wall one cell thin still shows, which matplotlib's
nearest resampling of a larger image would skip. A grid that fits is drawn cell for cell. Two 3D
clouds (LiDAR maps, outdoors as a rule: a scatter of points, not walls) are drawn as a bird's-eye
density instead: each pixel's shade is the share of its cells that are occupied. Feature
markers of one kind are thinned to one per :data:`~pcmapq.report.style.THIN_PX` pixels square
(:data:`~pcmapq.report.style.THIN_PX_DENSITY` on a density).
"""

from __future__ import annotations

import io
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.legend import Legend  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar  # noqa: E402

from pcmapq.raster.pool import max_pool  # noqa: E402
from pcmapq.report.arrows import (  # noqa: E402
    ARROW_WORDS,
    NICE,
    arrow_label,
    arrow_scale,
    feature_arrows,
    region_arrows,
)
from pcmapq.report.canvas import (  # noqa: E402
    density,
    extent,
    frame,
    grown,
    overlay,
    pooling,
    shade,
    size_m,
    thinned,
    window,
)
from pcmapq.report.relief import draw_top_view, has_relief, relief_panels  # noqa: E402
from pcmapq.report.rooms_layer import draw_rooms, rooms_legend  # noqa: E402
from pcmapq.report.style import (  # noqa: E402
    DPI,
    EXTRA,
    FOOTPRINT,
    MAP_LIGHT,
    MATCHED,
    MISSING,
    TEXT_PT,
    THIN_PX,
    THIN_PX_DENSITY,
    TITLE_PT,
    TRUTH_DARK,
    WIDTH_IN,
)
from pcmapq.report.text import score  # noqa: E402
from pcmapq.results.result import DetectorResult, Result  # noqa: E402


def _nice(value: float) -> float:
    """The largest 1, 2 or 5 times a power of ten not above ``value``."""
    power = 10.0 ** np.floor(np.log10(value))
    return max(n * power for n in NICE if n * power <= value)


def _title(ax: Axes, result: Result, name: str) -> None:
    m = result.detectors[name].matching
    note = result.note(name)
    ax.set_title(f"{name}: quality {score(m.quality, 2)}, precision {score(m.precision, 2)}, "
                 f"f1 {score(m.f1, 2)}" + (f"\n{textwrap.fill(note, 60)}" if note else ""),
                 fontsize=TITLE_PT)


def _scale_bar(ax: Axes) -> None:
    """A bar of a round length (about a fifth of the axes' width), right-aligned under the axes
    at the x label's height."""
    bar = _nice(abs(np.diff(ax.get_xlim())[0]) / 5)
    ax.add_artist(AnchoredSizeBar(ax.transData, bar, f"{bar:g} m", "upper right",
                                  bbox_to_anchor=(1.0, 0.0), bbox_transform=ax.transAxes,
                                  borderpad=1.9, pad=0, sep=2, frameon=False,
                                  size_vertical=0, fontproperties={"size": TEXT_PT}))
    ax.artists[-1].size_bar.get_children()[0].set_linewidth(2.5)


def _panel(ax: Axes, result: Result, box: tuple[float, float, float, float], image: np.ndarray,
           footprint: np.ndarray | None, det: DetectorResult, gain: float,
           cell_m: float) -> None:
    """One detector's panel over ``image`` and ``footprint``, the pooled rasters of the
    ``box`` (left, right, bottom, top; metres); markers thinned to one per ``cell_m`` metres
    square, arrows ``gain`` times their displacement."""
    ax.imshow(image, extent=box, origin="upper", interpolation="nearest")
    if footprint is not None:
        ax.contour(footprint, levels=[0.5], colors=FOOTPRINT, linewidths=0.8, extent=box,
                   origin="upper")
    m = det.matching
    if det.truth.labels is not None and result.rooms is not None:  # rooms: shaded by status
        draw_rooms(ax, result, det)
    if det.truth.segments is not None:  # Hough: draw the segments themselves
        for idx, feats, colour in ((m.truth_idx, det.truth, MATCHED),
                                   (m.missing, det.truth, MISSING), (m.extra, det.map, EXTRA)):
            ax.add_collection(LineCollection(feats.segments[idx].reshape(-1, 2, 2),
                                             colors=colour, linewidths=1.2))
    matched = thinned(det.truth_xy, cell_m)
    missing = det.truth.xy[m.missing][thinned(det.truth.xy[m.missing], cell_m)]
    extra = det.map.xy[m.extra][thinned(det.map.xy[m.extra], cell_m)]
    ax.scatter(*det.truth_xy[matched].T, s=9, c=MATCHED, zorder=3)
    ax.scatter(*missing.T, s=28, c=MISSING, marker="x", zorder=3)
    ax.scatter(*extra.T, s=28, c=EXTRA, marker="+", zorder=3)
    if len(matched):
        tails, vectors = feature_arrows(det)
        ax.quiver(*tails[matched].T, *vectors[matched].T, angles="xy", scale_units="xy",
                  scale=1.0 / gain, color="black", width=0.003, zorder=4)
    _scale_bar(ax)


def _regions_panel(ax: Axes, result: Result, box: tuple[float, float, float, float],
                   image: np.ndarray, gain: float) -> None:
    """The consistency map over ``image`` (the pooled raster of the ``box``, metres): at each
    region of the map, an arrow from where the region fits the truth on its own to where the
    map has it, ``gain`` times its length; held regions black, the others grey."""
    c = result.consistency
    ax.imshow(image, extent=box, origin="upper", interpolation="nearest")
    tails, vectors = region_arrows(result)
    for held, colour in ((False, "0.6"), (True, "black")):
        k = c.held == held
        if k.any():
            ax.quiver(*tails[k].T, *vectors[k].T, angles="xy", scale_units="xy",
                      scale=1.0 / gain, color=colour, width=0.004, zorder=4)
    if (largest := c.largest()) is not None:  # ringed where its arrow starts
        ax.scatter(*tails[largest], s=90, facecolors="none", edgecolors=MISSING, zorder=5)
    _scale_bar(ax)


def _legend_handles(result: Result, gain: float, as_density: bool) -> list[Line2D]:
    what = "occupied share" if as_density else "walls"
    handles = [Line2D([], [], color=TRUTH_DARK, lw=4, label=f"truth {what}"),
               Line2D([], [], color=MAP_LIGHT, lw=4, label=f"aligned map {what}"),
               Line2D([], [], color=MATCHED, marker="o", ls="", label="matched (truth)"),
               Line2D([], [], color="black", marker=r"$\rightarrow$", ls="", ms=12,
                      label=arrow_label(gain)),
               Line2D([], [], color=MISSING, marker="x", ls="", label="missing in the map"),
               Line2D([], [], color=EXTRA, marker="+", ls="", label="extra in the map")]
    if not result.full:
        handles.append(Line2D([], [], color=FOOTPRINT, lw=1, label="map footprint"))
    if _has_regions(result):
        handles.append(Line2D([], [], color=MISSING, marker="o", mfc="none", ls="",
                              label="region with the largest offset (grey arrow: not "
                              "held)"))
    if result.rooms is not None:
        handles += rooms_legend(result.rooms)
    return handles


def _has_regions(result: Result) -> bool:
    """Whether the result has a consistency map to draw."""
    return result.consistency is not None and len(result.consistency.points) > 0


def fitted_legend(fig: Figure, handles: list[Line2D], note: str,
                  spare: Axes | None = None) -> Legend:
    """A legend titled ``note``: centred in the ``spare`` axes (an empty panel cell, its frame
    hidden) when there is one, else below the panels in as many columns as fit the figure's
    width (one a row at worst)."""
    options = {"handles": handles, "fontsize": TEXT_PT, "title_fontsize": TEXT_PT,
               "frameon": False}
    if spare is not None:
        spare.set_axis_off()
        return spare.legend(loc="center", title=textwrap.fill(note, 40), **options)
    renderer = fig.canvas.get_renderer()
    for ncols in range(len(handles), 0, -1):
        legend = fig.legend(loc="outside lower center", ncols=ncols, title=note, **options)
        if ncols == 1 or legend.get_window_extent(renderer).width <= 0.98 * fig.bbox.width:
            return legend
        legend.remove()
    raise AssertionError("unreachable")


def _grid_shape(n: int) -> tuple[int, int]:
    """(rows, cols) of the panels of ``n`` detectors: one column for one, else two."""
    cols = 1 if n == 1 else 2
    return -(-n // cols), cols


def vectorial_figure(result: Result, scale: float | None = None,
                     relief: bool = True) -> Figure:
    """One panel per detector: the truth dark over the aligned map light, matched features with
    their displacement arrows, missing truth features and extra map features (thinned where
    crowded), the footprint outline; then the regions' panel; then, for two 3D clouds (and
    ``relief``), the 3D consistency map's top view and side profile
    (:mod:`pcmapq.report.relief`); over the part of the truth grid that holds walls
    (:func:`~pcmapq.report.canvas.window`). Every arrow is ``scale`` times its length (None:
    :func:`~pcmapq.report.arrows.auto_arrow_scale`)."""
    gain = arrow_scale(result, scale)
    names = list(result.detectors)
    shown = window(result)
    width, height = size_m(result, shown)
    relief = relief and has_relief(result)
    panels = len(names) + _has_regions(result) + 2 * relief
    rows, cols = _grid_shape(panels)
    panel_w = WIDTH_IN / cols
    spare = rows * cols > panels
    panel_h = float(np.clip(panel_w * height / max(width, 1e-9), 2.5, 9.0)) + 0.6
    fig, grid = plt.subplots(rows, cols, figsize=(WIDTH_IN, rows * panel_h + (0 if spare else 1)),
                             squeeze=False, layout="constrained")
    axes = list(grid.flat[:panels])
    as_density = density(result)
    thin_px = THIN_PX_DENSITY if as_density else THIN_PX
    fitted_legend(fig, _legend_handles(result, gain, as_density),
                  f"markers thinned to one per {thin_px} px square where crowded; "
                  f"{'shade: share of occupied cells per pixel; ' if as_density else ''}"
                  f"{ARROW_WORDS}; axes and arrows in metres", grid.flat[-1] if spare else None)
    for ax, name in zip(axes, names, strict=False):
        _title(ax, result, name)
    plans = axes[:-1] if relief else axes  # every panel but the side profile shows the plan
    if _has_regions(result):
        plans[len(names)].set_title(f"{result.overlap.verdict}: each region's fit\non its own",
                                    fontsize=TITLE_PT)
    colours = relief_panels(fig, axes[-2], axes[-1], result) if relief else None
    for ax in plans:
        frame(ax, result, shown)
    factor, pixel_m = pooling(fig, plans, result.truth_occupied[shown].shape)
    box = extent(result, factor, shown)
    image = overlay(shade(result.truth_occupied[shown], factor, as_density),
                    grown(shade(result.map_occupied[shown], factor, as_density)))
    footprint = None if result.full else max_pool(result.overlap.footprint[shown], factor)
    for ax, name in zip(axes, names, strict=False):
        _panel(ax, result, box, image, footprint, result.detectors[name], gain,
               thin_px * pixel_m)
    if _has_regions(result):
        _regions_panel(plans[len(names)], result, box, image, gain)
    if colours is not None:
        draw_top_view(axes[-2], result, box, image, colours)
    return fig


#: Metadata that makes a figure file the same on every run (no date), by format.
_FIXED_METADATA = {"png": {}, "svg": {"Date": None}, "pdf": {"CreationDate": None,
                                                             "ModDate": None}}


def figure_bytes(fig: Figure, fmt: str, dpi: int = DPI) -> bytes:
    """The figure as a ``fmt`` file ("png", "svg" or "pdf"), the same bytes on every run
    (then closed)."""
    buf = io.BytesIO()
    with plt.rc_context({"svg.hashsalt": "pcmapq"}):  # SVG ids the same on every run
        fig.savefig(buf, format=fmt, dpi=dpi, metadata=_FIXED_METADATA[fmt])
    plt.close(fig)
    return buf.getvalue()


def png_bytes(fig: Figure, dpi: int = DPI) -> bytes:
    """The figure as PNG bytes (then closed)."""
    return figure_bytes(fig, "png", dpi)
