"""Pictures of a tracked run (``pcmapq track``): its figures against distance travelled, one
panel per family, the worst drop marked; the vectorial map of one step with the robot's path;
and the HTML report that holds both. Works on the flat step rows of
:func:`pcmapq.track.outputs.step_rows` (metres, degrees), so it needs nothing of the run."""

from __future__ import annotations

import html

import numpy as np
from matplotlib.figure import Figure

from pcmapq.core.words import count
from pcmapq.report.html import STYLE, _img, _table
from pcmapq.report.plot import png_bytes, vectorial_figure
from pcmapq.report.style import DETECTOR_COLOURS, OTHER_COLOURS, WIDTH_IN
from pcmapq.report.text import number
from pcmapq.results.result import Result

#: The panels: a title and the columns drawn in it (those the rows have).
FAMILIES = (
    ("feature quality (truth features found)", ("harris_quality", "hough_quality",
                                                 "sift_quality")),
    ("feature precision (map features right)", ("harris_precision", "hough_precision",
                                                 "sift_precision", "precision")),
    ("coverage, wall precision", ("coverage", "wall_precision@0.05m", "wall_precision@0.1m",
                                  "wall_precision@0.2m")),
    ("wall distances [m]", ("accuracy_mean_m", "completeness_mean_m")),
    ("alignment [m]: offset of the newest part, slide of the first", ("local_offset_m",
                                                                        "slide_m")),
    ("3D structures (two 3D clouds): f1 of the planes and of the lines where two meet",
     ("planes_f1", "plane_lines_f1")),
    ("3D [m]: AWD, the 3D consistency map's largest offset", ("awd_m", "largest_offset_3d_m")),
    ("absolute pose error, APE [m]", ("ape_rmse_m", "ape_max_m")),
    ("relative pose error, RPE: translation [m]", ("rpe_rmse_m",)),
    ("relative pose error, RPE: rotation [deg]", ("rpe_rot_rmse_deg",)),
)
#: The least height of a panel in metres (degrees): centimetre (tenth-degree) noise stays flat.
MIN_METRES, MIN_DEGREES = 0.1, 0.5
#: The path over the vectorial map, drawn over a white edge above every marker.
PATH_COLOUR, PATH_Z = "#08306b", 10
#: The inputs' table reads left to right, a long path or command breaks anywhere rather than
#: widen the page, and the table of steps scrolls inside its own box when wider than the page.
FACTS_STYLE = """.facts td { text-align: left; }
.sub, .facts td, code { overflow-wrap: anywhere; }
.steps { max-width: 100%; overflow-x: auto; } .steps table { margin: 0; }
.steps th { vertical-align: bottom; } .steps td { white-space: nowrap; }
"""
#: Column names in the table of steps break after these characters, so it fits a 1400 px window.
BREAKS = "_@"
#: The columns of the report's table of steps, those the rows have, and their decimals.
TABLE = {"step": 0, "scans": 0, "distance_m": 1, "harris_quality": 3, "hough_quality": 3,
         "sift_quality": 3, "precision": 3, "wall_precision@0.1m": 3, "coverage": 3,
         "accuracy_mean_m": 3, "local_offset_m": 3, "slide_m": 3, "ape_rmse_m": 3, "rpe_rmse_m": 3,
         "rpe_rot_rmse_deg": 2}


def _colour(column: str, index: int) -> str:
    """A curve's colour: its detector's (``harris_quality``), else the ``index``-th other."""
    for name, colour in DETECTOR_COLOURS.items():
        if column.startswith(f"{name}_"):
            return colour
    return OTHER_COLOURS[index % len(OTHER_COLOURS)]


def drop_words(rows: list[dict], drop: dict | None) -> str:
    """The worst drop in words: how far the figure fell, from which step to which, how far
    later steps came back, and where the fall started; or that there was none."""
    if drop is None:
        return "no lasting drop of precision (none of at least 0.05)"
    figure, peak, low, start = drop["figure"], drop["peak"], drop["low"], drop["start"]
    later = [r[figure] for r in rows[low + 1:] if r.get(figure) is not None]
    after = (f", and no later step came back above {max(later):.3f}" if later else
             ", the last step scored")
    return (f"{figure} fell {drop['size']:.3f}, from {rows[peak][figure]:.3f} at step {peak} "
            f"to {rows[low][figure]:.3f} at step {low}{after}; the fall starts at step "
            f"{start} ({where(rows[start])})")


def recorded(rows: list[dict]) -> bool:
    """Whether the rows are a recording's published maps (on its time axis, no distance)."""
    return all(r["distance_m"] is None for r in rows)


def where(row: dict) -> str:
    """Where a step stands on its run's axis: ``120 m`` travelled, or ``45.2 s`` into a
    recording."""
    return f"{row['time_s']:.1f} s" if row["distance_m"] is None else \
        f"{row['distance_m']:.0f} m"


def timeline_figure(rows: list[dict], drop: dict | None, title: str = "") -> Figure:
    """The figures of the rows against ``distance_m`` (a recording's: ``time_s``), one panel
    per family that has data; a
    gap where a step was not scored; the worst drop (``drop``: peak, start, low step indices)
    shaded from its peak to its lowest step, a line where it starts; ``title`` above (the
    run)."""
    axis = "time_s" if recorded(rows) else "distance_m"
    distance = np.array([r[axis] for r in rows], dtype=float)
    panels = [(title, [c for c in cols if any(r.get(c) is not None for r in rows)])
              for title, cols in FAMILIES]
    panels = [(t, cols) for t, cols in panels if cols]
    if not panels:
        fig = Figure(figsize=(WIDTH_IN, 1.5))
        fig.text(0.5, 0.5, f"no step could be scored ({count(len(rows), 'step')})", ha="center",
                 va="center")
        return fig
    fig = Figure(figsize=(WIDTH_IN, 2.0 * len(panels) + 0.6), layout="constrained")
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for ax, (panel, cols) in zip(axes, panels, strict=True):
        for i, column in enumerate(cols):
            values = np.array([np.nan if r.get(column) is None else r[column] for r in rows])
            ax.plot(distance, values, marker=".", lw=1.2, label=column,
                    color=_colour(column, i), ls="--" if column == "precision" else "-")
        ax.set_title(panel, fontsize=9, loc="left")
        top = np.nanmax([r.get(c) or 0.0 for r in rows for c in cols] + [0.0])
        least = (MIN_METRES if "[m]" in panel else MIN_DEGREES if "[deg]" in panel else None)
        ax.set_ylim(0.0, max(1.02, top * 1.05) if least is None else max(least, top * 1.1))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5), frameon=False)
        if drop is not None:
            ax.axvspan(distance[drop["peak"]], distance[drop["low"]], color="#ee6677",
                       alpha=0.12, lw=0)
            ax.axvline(distance[drop["start"]], color="#ee6677", lw=1.2)
    axes[-1].set_xlabel("time since the recording's start [s]" if axis == "time_s" else
                        "distance travelled [m]")
    marks = ("" if drop is None else
             "\nshaded: from the peak to the lowest step; red line: where the fall starts")
    fig.suptitle((f"{title}\n" if title else "") + drop_words(rows, drop) + marks,
                 fontsize=9)
    return fig


def path_figure(result: Result, path_xy: np.ndarray) -> Figure:
    """The vectorial map of one step with the robot's path so far over it (``path_xy`` (K, 2),
    truth frame, metres), its first position a square, its last a dot, above every marker."""
    from matplotlib import patheffects

    fig = vectorial_figure(result)
    if len(path_xy) == 0:  # a recording's maps: no path
        return fig
    edge = [patheffects.withStroke(linewidth=3.2, foreground="white")]
    for ax in fig.axes:
        if ax.get_title():
            ax.plot(path_xy[:, 0], path_xy[:, 1], color=PATH_COLOUR, lw=1.4,
                    zorder=PATH_Z, path_effects=edge)
            ax.plot(*path_xy[0], marker="s", color=PATH_COLOUR, ms=6, mec="white",
                    zorder=PATH_Z + 1)
            ax.plot(*path_xy[-1], marker="o", color=PATH_COLOUR, ms=7, mec="white",
                    zorder=PATH_Z + 1)
    fig.suptitle("the robot's path so far (estimated poses, aligned with the map): dark blue "
                 "line from its first position (square) to its last (dot)", fontsize=9)
    return fig


def timeline_html(rows: list[dict], drop: dict | None, shown: int, result: Result | None,
                  path_xy: np.ndarray | None, *, inputs: dict[str, str],
                  command: str | None, asked: bool = False, curves: bytes | None = None) -> str:
    """The report: the inputs (``inputs``: what each is, in words, by name: run, poses, truth,
    reference poses, step rule), the curves (``curves``: their PNG when already drawn by
    :func:`timeline_figure`), the step ``shown`` (its vectorial map with the path, or why it
    was not scored; ``asked``: chosen with ``--step``) and a table of every step."""
    step = rows[shown]
    scored = sum(bool(r["scored"]) for r in rows)
    unit = ("map", " published") if recorded(rows) else ("scan", "")
    facts = "".join(f"<tr><td>{html.escape(k)}</td><td>{html.escape(v)}</td></tr>"
                    for k, v in inputs.items())
    parts = [f"<h1>pcmapq track</h1><p class='sub'>{html.escape(inputs.get('run', ''))}"
             f" against {html.escape(inputs.get('truth', ''))}: {count(len(rows), 'step')}, "
             f"{scored} scored, of {count(rows[-1]['scans'], unit[0])}{unit[1]}</p>",
             f"<table class='facts'>{facts}</table>",
             f"<p>command: <code>{html.escape(command or '(called from Python)')}</code></p>",
             "<h2>Quality over the run</h2>",
             f"<p>{html.escape(drop_words(rows, drop))}.</p>",
             _img(curves or png_bytes(timeline_figure(rows, drop)), "figures against distance")]
    what = ("the step asked" if asked else "where the worst drop starts"
            if drop is not None and drop["start"] == shown else "the last step; no drop")
    parts.append(f"<h2>Step {shown} ({what}): map {step['scans']} of {rows[-1]['scans']}, "
                 f"published at {where(step)}</h2>" if recorded(rows) else
                 f"<h2>Step {shown} ({what}): {step['scans']} of "
                 f"{count(rows[-1]['scans'], 'scan')}, "
                 f"{step['distance_m']:.0f} m travelled</h2>")
    if result is not None and path_xy is not None:
        parts.append(_img(png_bytes(path_figure(result, path_xy)),
                          f"vectorial map at step {shown}"))
    else:
        parts.append(f"<p class='note'>not scored: {html.escape(str(step['note']))}</p>")
    columns = [("time_s" if c == "distance_m" and recorded(rows) else c) for c in TABLE
               if c in step]
    marks = {shown: " (shown)"} | ({} if drop is None else
                                   {drop["peak"]: " (peak)", drop["start"]: " (fall starts)",
                                    drop["low"]: " (lowest)"})
    parts.append("<h2>Steps</h2><div class='steps'>" + _table(columns, [
        [_cell(r[c], TABLE.get(c, 1)) + (marks.get(r["step"], "") if c == "step" else "")
         for c in columns] for r in rows], BREAKS) + "</div>")
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><meta "
            "name='viewport' content='width=device-width, initial-scale=1'><title>pcmapq "
            f"track</title><style>{STYLE}{FACTS_STYLE}</style></head><body>{''.join(parts)}"
            "</body></html>\n")


def _cell(value: object, digits: int) -> str:
    """A table cell: the number with ``digits`` decimals, '-' for none."""
    if isinstance(value, float):
        return number(value, digits)
    return "-" if value is None else str(value)
