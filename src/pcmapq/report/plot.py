"""Pictures of a Result: the vectorial map per detector, and the map-to-truth distance heatmap.

Everything is drawn in the truth frame, axes in metres (matplotlib, headless Agg backend).
"""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar  # noqa: E402

from pcmapq.metrics.distances import nearest_distance  # noqa: E402
from pcmapq.report.text import score  # noqa: E402
from pcmapq.result import DetectorResult, Result  # noqa: E402

TRUTH_GREY, MAP_BLUE = (0.62, 0.62, 0.62), (0.25, 0.55, 0.95)
MATCHED, MISSING, EXTRA, FOOTPRINT = "#1a9850", "#d73027", "#f28e2b", "#7b3294"
NICE = (1, 2, 5)


def _nice(value: float) -> float:
    """The largest 1, 2 or 5 times a power of ten not above ``value``."""
    power = 10.0 ** np.floor(np.log10(value))
    return max(n * power for n in NICE if n * power <= value)


def extent(result: Result) -> tuple[float, float, float, float]:
    """(left, right, bottom, top) of the truth grid, metres (yaw of the grid ignored)."""
    x0, y0, _ = result.grid.origin
    width, height = result.grid.size_m
    return x0, x0 + width, y0, y0 + height


def overlay(result: Result) -> np.ndarray:
    """RGB image: white, the truth's walls grey, the aligned map's walls blue over them."""
    img = np.ones((*result.grid.shape, 3))
    img[result.truth_occupied] = TRUTH_GREY
    img[result.map_occupied] = MAP_BLUE
    return img


def arrow_gain(result: Result) -> float:
    """How much displacement arrows are lengthened: a 1, 2 or 5 step chosen so that the
    largest displacement draws about 4 % of the map's width."""
    d = np.concatenate([det.distances for det in result.detectors.values()] + [np.zeros(1)])
    if d.max() <= 0:
        return 1.0
    return max(1.0, _nice(0.04 * result.grid.size_m[0] / d.max()))


def _panel(ax, result: Result, name: str, det: DetectorResult, gain: float) -> None:
    ax.imshow(overlay(result), extent=extent(result), origin="upper", interpolation="nearest")
    if not result.full:
        ax.contour(result.overlap.footprint, levels=[0.5], colors=FOOTPRINT, linewidths=0.8,
                   extent=extent(result), origin="upper")
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
    ax.set_title(f"{name}: quality {score(m.quality, 2)}, precision {score(m.precision, 2)}, "
                 f"f1 {score(m.f1, 2)}"
                 + (f"\n{note}" if (note := result.note(name)) else ""), fontsize=10)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")


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
    for ax, name in zip(axes[0], names, strict=True):
        _panel(ax, result, name, result.detectors[name], gain)
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
    return fig


def distance_heatmap(result: Result, clip: float = 0.5) -> Figure:
    """Each occupied cell of the aligned map coloured by its distance to the nearest truth wall,
    metres (clipped at ``clip``); the truth's walls in grey beneath."""
    dist = nearest_distance(result.truth_occupied, result.grid)
    shown = np.where(result.map_occupied, np.minimum(dist, clip), np.nan)
    width, height = result.grid.size_m
    fig, ax = plt.subplots(figsize=(8.0, float(np.clip(8.0 * height / width, 3.0, 10.0))),
                           layout="constrained")
    base = np.ones((*result.grid.shape, 3))
    base[result.truth_occupied] = (0.82, 0.82, 0.82)
    ax.imshow(base, extent=extent(result), origin="upper", interpolation="nearest")
    im = ax.imshow(shown, extent=extent(result), origin="upper", cmap="viridis", vmin=0,
                   vmax=clip, interpolation="nearest")
    fig.colorbar(im, ax=ax, label=f"map-to-truth distance [m] (clipped at {clip:g})",
                 shrink=0.8)
    ax.set_title("distance from each map wall cell to the nearest truth wall", fontsize=10)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return fig


def png_bytes(fig: Figure, dpi: int = 130) -> bytes:
    """The figure as PNG bytes (then closed)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()
