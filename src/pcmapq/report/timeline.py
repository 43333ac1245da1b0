"""Pictures of a tracked run (``pcmapq track``): its figures against distance travelled, one
panel per family, the worst drop marked; the vectorial map of one step with the robot's path;
and the HTML report that holds both. Works on the flat step rows of
:func:`pcmapq.track.outputs.step_rows` (metres, degrees), so it needs nothing of the run."""

from __future__ import annotations

import html

import numpy as np
from matplotlib.figure import Figure

from pcmapq.report.html import STYLE, _img, _table
from pcmapq.report.plot import WIDTH_IN, png_bytes, vectorial_figure
from pcmapq.report.summary import COLOURS
from pcmapq.report.text import number
from pcmapq.result import Result

#: The panels: a title and the columns drawn in it (those the rows have).
FAMILIES = (
    ("feature quality (truth features found)", ("harris_quality", "hough_quality",
                                                 "sift_quality")),
    ("feature precision (map features right)", ("harris_precision", "hough_precision",
                                                 "sift_precision", "precision")),
    ("coverage, wall precision", ("coverage", "wall_precision@0.05m", "wall_precision@0.1m",
                                  "wall_precision@0.2m")),
    ("wall distances [m]", ("accuracy_mean_m", "completeness_mean_m")),
    ("alignment: slide of the first part [m]", ("slide_m",)),
    ("trajectory error [m]", ("ape_rmse_m", "rpe_rmse_m")),
)
#: Colours of the columns that are not a detector's.
OTHER = ("#222222", "#aa3377", "#66ccee", "#ccbb44", "#bbbbbb")
#: The least height of a panel in metres: centimetre noise stays flat.
MIN_METRES = 0.1
#: The path over the vectorial map.
PATH_COLOUR = "#08306b"


def _colour(column: str, index: int) -> str:
    for name, colour in COLOURS.items():
        if column.startswith(name):
            return colour
    return OTHER[index % len(OTHER)]


def timeline_figure(rows: list[dict], drop: dict | None) -> Figure:
    """The figures of the rows against ``distance_m``, one panel per family that has data; a
    gap where a step was not scored; the worst drop (``drop``: peak, start, low step indices)
    shaded from its peak to its lowest step, a line where it starts."""
    distance = np.array([r["distance_m"] for r in rows], dtype=float)
    panels = [(title, [c for c in cols if any(r.get(c) is not None for r in rows)])
              for title, cols in FAMILIES]
    panels = [(t, cols) for t, cols in panels if cols]
    if not panels:
        fig = Figure(figsize=(WIDTH_IN, 1.5))
        fig.text(0.5, 0.5, f"no step could be scored ({len(rows)} steps)", ha="center",
                 va="center")
        return fig
    fig = Figure(figsize=(WIDTH_IN, 2.0 * len(panels) + 0.6), layout="constrained")
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for ax, (title, cols) in zip(axes, panels, strict=True):
        for i, column in enumerate(cols):
            values = np.array([np.nan if r.get(column) is None else r[column] for r in rows])
            ax.plot(distance, values, marker=".", lw=1.2, label=column,
                    color=_colour(column, i), ls="--" if column == "precision" else "-")
        ax.set_title(title, fontsize=9, loc="left")
        top = np.nanmax([r.get(c) or 0.0 for r in rows for c in cols] + [0.0])
        ax.set_ylim(0.0, max(1.02, top * 1.05) if "[m]" not in title else
                    max(MIN_METRES, top * 1.1))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5), frameon=False)
        if drop is not None:
            ax.axvspan(distance[drop["peak"]], distance[drop["low"]], color="#ee6677",
                       alpha=0.12, lw=0)
            ax.axvline(distance[drop["start"]], color="#ee6677", lw=1.2)
    axes[-1].set_xlabel("distance travelled [m]")
    if drop is not None:
        fig.suptitle(f"worst drop of {drop['figure']}: {drop['size']:.3f}, starting at step "
                     f"{drop['start']} ({distance[drop['start']]:.0f} m)", fontsize=10)
    return fig


def path_figure(result: Result, path_xy: np.ndarray) -> Figure:
    """The vectorial map of one step with the robot's path so far over it (``path_xy`` (K, 2),
    truth frame, metres) and its last position marked."""
    fig = vectorial_figure(result)
    fig.suptitle("the robot's path so far: dark blue line, its last position: dot", fontsize=9)
    for ax in fig.axes:
        if ax.get_title():
            ax.plot(path_xy[:, 0], path_xy[:, 1], color=PATH_COLOUR, lw=0.8, alpha=0.8)
            ax.plot(*path_xy[-1], marker="o", color=PATH_COLOUR, ms=5)
    return fig


def timeline_html(rows: list[dict], drop: dict | None, shown: int, result: Result | None,
                  path_xy: np.ndarray | None, *, run: str, truth: str,
                  command: str | None) -> str:
    """The report: inputs, the curves, the step ``shown`` (its vectorial map with the path, or
    why it was not scored) and a table of every step."""
    step = rows[shown]
    parts = [f"<h1>pcmapq track</h1><p class='sub'>{html.escape(run)} against "
             f"{html.escape(truth)}</p>",
             f"<p>command: <code>{html.escape(command or '(called from Python)')}</code></p>",
             "<h2>Quality over the run</h2>",
             _img(png_bytes(timeline_figure(rows, drop)), "figures against distance")]
    what = "the worst drop" if drop is not None and drop["start"] == shown else "the step asked"
    parts.append(f"<h2>Step {shown} ({what}): {step['scans']} scans, "
                 f"{step['distance_m']:.0f} m travelled</h2>")
    if result is not None and path_xy is not None:
        parts.append(_img(png_bytes(path_figure(result, path_xy)),
                          f"vectorial map at step {shown}"))
    else:
        parts.append(f"<p class='note'>not scored: {html.escape(str(step['note']))}</p>")
    columns = ["step", "scans", "distance_m", "harris_quality", "hough_quality",
               "sift_quality", "precision", "coverage", "accuracy_mean_m", "slide_m"]
    columns = [c for c in columns if c in step]
    parts.append("<h2>Steps</h2>" + _table(columns, [
        [number(r[c]) if isinstance(r[c], float) else ("" if r[c] is None else str(r[c]))
         for c in columns] for r in rows]))
    return ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>pcmapq track</title>"
            f"<style>{STYLE}</style></head><body>{''.join(parts)}</body></html>\n")
