"""The 3D consistency map's pictures (two 3D clouds, :mod:`pcmapq.align.regions3d`): where a map
sinks or rises. A top view of the map's tiles, each coloured by its region's vertical offset dz
(diverging, white at 0, a colour bar in metres) over the map's density in grey, and a side
profile: each region's dz against its distance along the map's main axis. Regions that are
stretches of the run are drawn as their centroids, joined in the run's order and labelled by
their scans, and profiled against the run (each stretch's middle scan). dz is the map's
error: below 0 the map has the region too low (blue), above too high (red). Truth frame
levelled (x, y the truth's plan), metres; regions that are not held are drawn faint and
hatched (their offset is not sure)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.collections import PatchCollection
from matplotlib.colors import Normalize
from matplotlib.patches import Rectangle

from pcmapq.report.style import TEXT_PT, TITLE_PT, WIDTH_IN
from pcmapq.results.result import Result

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from pcmapq.align.regions3d import Consistency3D

#: The diverging colour map of dz: blue low, white level, red high.
CMAP = "RdBu_r"
#: The colour scale spans at least +- this, metres (a level map stays pale).
MIN_SPAN_M = 0.05
#: Opacity of a held region's tile, and of one not held.
HELD_ALPHA, LOOSE_ALPHA = 0.85, 0.35


def has_relief(result: Result) -> bool:
    """Whether the result has a 3D consistency map with regions to draw."""
    return result.consistency_3d is not None and len(result.consistency_3d.points) > 0


def _span(c: Consistency3D) -> float:
    """The colour scale's half span, metres: the largest |dz| of the held regions (of all when
    none is held), at least MIN_SPAN_M, rounded up to 1, 2 or 5 times a power of ten."""
    dz = np.abs(c.offset[c.held, 2] if c.held.any() else c.offset[:, 2])
    top = max(float(dz.max(initial=0.0)), MIN_SPAN_M)
    power = 10.0 ** np.floor(np.log10(top))
    return next(n * power for n in (1, 2, 5, 10) if n * power >= top - 1e-12)


def relief_colours(result: Result) -> ScalarMappable:
    """dz -> colour: CMAP over +- the span of :func:`_span`, metres."""
    span = _span(result.consistency_3d)
    return ScalarMappable(Normalize(-span, span), CMAP)


def main_axis(c: Consistency3D) -> tuple[np.ndarray, np.ndarray]:
    """The map's main axis in the plan: the regions' centroid (2,) and the unit direction (2,)
    along which their centres (weighted by their points) spread most, pointing to +x (or +y
    when it runs along y)."""
    w = c.points / max(c.points.sum(), 1)
    mean = w @ c.centre[:, :2]
    d = c.centre[:, :2] - mean
    _, vectors = np.linalg.eigh((d * w[:, None]).T @ d)
    axis = vectors[:, -1]
    return mean, axis if axis[np.argmax(np.abs(axis))] > 0 else -axis


def relief_panels(fig: Figure, top: Axes, side: Axes, result: Result) -> ScalarMappable:
    """Titles both panels, draws the side profile on ``side`` and the colour bar under
    ``top`` (before the figure is laid out); the colours, for :func:`draw_top_view`."""
    c = result.consistency_3d
    colours = relief_colours(result)
    top.set_title(f"3D: each region's vertical offset dz ({c.tile_m:g} m tiles; hatched: not "
                  "held)" if c.scans is None else f"3D: the vertical offset dz of each stretch "
                  f"of {c.stretch} scans (hollow: not held)", fontsize=TITLE_PT)
    bar = fig.colorbar(colours, ax=top, location="bottom", shrink=0.8, aspect=30)
    bar.set_label("dz [m], the map's region from its fit to the truth (< 0: too low)",
                  fontsize=TEXT_PT)
    bar.ax.tick_params(labelsize=TEXT_PT)
    _profile(side, c, colours)
    return colours


def _profile(ax: Axes, c: Consistency3D, colours: ScalarMappable) -> None:
    """Each region's dz (metres) against its distance along the map's main axis, or a
    stretch's against its middle scan."""
    if c.scans is None:
        mean, axis = main_axis(c)
        along = (c.centre[:, :2] - mean) @ axis
        mean = np.round(mean, 1) + 0.0  # as the label writes it, never "-0.0"
        label = (f"along the map's main axis ({axis[0]:.2f}, {axis[1]:.2f}) from "
                 f"({mean[0]:.1f}, {mean[1]:.1f}) [m]")
    else:
        along, label = c.scans.mean(axis=1), "along the run: each stretch's middle scan"
    dz = c.offset[:, 2]
    ax.axhline(0.0, color="0.6", lw=0.8, zorder=1)
    loose = ~c.held
    ax.scatter(along[loose], dz[loose], s=22, facecolors="none", edgecolors="0.55", zorder=2,
               label="not held")
    ax.scatter(along[c.held], dz[c.held], s=26, c=colours.to_rgba(dz[c.held]),
               edgecolors="black", linewidths=0.5, zorder=3, label="held")
    if (k := c.largest_dz()) is not None:
        ax.scatter(along[k], dz[k], s=140, facecolors="none", edgecolors="black", lw=1.2,
                   zorder=4, label="largest |dz|")
    span = colours.norm.vmax
    low, high = min(-span, dz.min(initial=0.0)), max(span, dz.max(initial=0.0))
    ax.set_ylim(low - 0.1 * (high - low), high + 0.1 * (high - low))
    ax.set_title(f"3D: side profile, dz along the {'map' if c.scans is None else 'run'}",
                 fontsize=TITLE_PT)
    ax.set_xlabel(label, fontsize=TEXT_PT)
    ax.set_ylabel("dz [m] (< 0: the map too low)", fontsize=TEXT_PT)
    ax.tick_params(labelsize=TEXT_PT)
    ax.legend(fontsize=TEXT_PT, frameon=False, loc="best")


def draw_top_view(ax: Axes, result: Result, box: tuple[float, float, float, float],
                  image: np.ndarray, colours: ScalarMappable) -> None:
    """The map's tiles (or stretches) coloured by dz over ``image`` (the pooled RGB picture of
    the ``box``, metres, shown in grey), the region with the largest |dz| ringed at its
    centroid."""
    c = result.consistency_3d
    grey = np.repeat(image.mean(axis=2, keepdims=True), 3, axis=2)
    ax.imshow(grey, extent=box, origin="upper", interpolation="nearest")
    if c.scans is None:
        _tiles(ax, c, colours)
    else:
        _stretches(ax, c, colours)
    if (k := c.largest_dz()) is not None:
        ax.scatter(*c.centre[k, :2], s=110, facecolors="none", edgecolors="black", lw=1.2,
                   zorder=5)


def _stretches(ax: Axes, c: Consistency3D, colours: ScalarMappable) -> None:
    """Each stretch of the run at its centroid, joined in the run's order, coloured by dz
    (hollow: not held); the first and the last labelled by their scans."""
    ax.plot(c.centre[:, 0], c.centre[:, 1], color="0.35", lw=0.8, zorder=3)
    rgba = colours.to_rgba(c.offset[:, 2])
    loose = ~c.held
    ax.scatter(*c.centre[loose, :2].T, s=60, facecolors="none", edgecolors="0.45", zorder=4)
    ax.scatter(*c.centre[c.held, :2].T, s=70, c=rgba[c.held], edgecolors="black",
               linewidths=0.5, zorder=4)
    for k, side in {0: -1, len(c.points) - 1: 1}.items():
        ax.annotate(c.scan_span(k), tuple(c.centre[k, :2]),
                    xytext=(6 * side, 6), textcoords="offset points", fontsize=TEXT_PT - 1,
                    ha="left" if side > 0 else "right", zorder=6)


def _tiles(ax: Axes, c: Consistency3D, colours: ScalarMappable) -> None:
    """Each tile coloured by dz (faint and hatched: not held)."""
    corners = np.floor(c.centre[:, :2] / c.tile_m) * c.tile_m
    rgba = colours.to_rgba(c.offset[:, 2])
    for held, alpha, hatch in ((True, HELD_ALPHA, None), (False, LOOSE_ALPHA, "///")):
        k = np.flatnonzero(c.held == held)
        if len(k) == 0:
            continue
        tiles = [Rectangle(tuple(corners[i]), c.tile_m, c.tile_m) for i in k]
        face = rgba[k].copy()
        face[:, 3] = alpha
        ax.add_collection(PatchCollection(tiles, facecolors=face, edgecolors="0.5",
                                          linewidths=0.3, hatch=hatch, zorder=3))


def relief_figure(result: Result) -> Figure:
    """The two pictures side by side, for the report: the top view over the map's density on
    the part of the truth grid a picture shows (:func:`~pcmapq.report.canvas.window`), and the
    side profile."""
    from matplotlib.figure import Figure

    from pcmapq.report.canvas import extent, frame, pooling, shade, size_m, window

    shown = window(result)
    width, height = size_m(result, shown)
    panel_h = float(np.clip(WIDTH_IN / 2 * height / max(width, 1e-9), 2.5, 9.0)) + 1.2
    fig = Figure(figsize=(WIDTH_IN, panel_h), layout="constrained")
    top, side = fig.subplots(1, 2)
    colours = relief_panels(fig, top, side, result)
    frame(top, result, shown)
    factor, _ = pooling(fig, [top], result.map_occupied[shown].shape)
    alpha = shade(result.map_occupied[shown], factor, True)
    image = np.repeat((1.0 - 0.7 * alpha)[..., None], 3, axis=2)
    draw_top_view(top, result, extent(result, factor, shown), image, colours)
    return fig
