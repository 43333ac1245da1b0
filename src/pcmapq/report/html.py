"""A self-contained HTML report of a Result: inputs, alignment, scores, figures (embedded, shown
at their own width so their fonts read as drawn), the lists of missing and extra features."""

from __future__ import annotations

import base64
import html
import json

import numpy as np

from pcmapq import __version__
from pcmapq.core.stats import Stats
from pcmapq.report import structures
from pcmapq.report.arrows import arrow_scale
from pcmapq.report.heatmap import distance_heatmap
from pcmapq.report.plot import png_bytes, vectorial_figure
from pcmapq.report.relief import has_relief, relief_figure
from pcmapq.report.style import FIGURE_WIDTH_PX
from pcmapq.report.text import map_3d_parts, number, relief_parts, score
from pcmapq.report.viewer import nearest_distances, viewer_html
from pcmapq.report.viewer_page import STYLE as VIEWER_STYLE
from pcmapq.results.result import DetectorResult, Result

STYLE = """
body { font-family: -apple-system, 'Segoe UI', Helvetica, Arial, sans-serif; margin: 2em auto;
       color: #222; padding: 0 1em; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; } h2 { font-size: 1.15em; margin-top: 1.6em;
     border-bottom: 1px solid #ddd; padding-bottom: 0.2em; }
.sub { color: #666; margin-top: 0; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.95em; }
th, td { padding: 0.3em 0.8em; text-align: right; border-bottom: 1px solid #e4e4e4; }
th { background: #f5f5f5; } td:first-child, th:first-child { text-align: left; }
img { max-width: 100%; border: 1px solid #eee; }
.note { color: #555; font-size: 0.9em; max-width: 70em; }
.lists { display: flex; flex-wrap: wrap; gap: 0 2em; }
.list { max-height: 16em; overflow-y: auto; border: 1px solid #eee; margin-bottom: 0.8em; }
.list table { margin: 0; }
h3 { font-size: 1em; margin: 0.8em 0 0.3em; }
""" + f"body {{ max-width: {FIGURE_WIDTH_PX + 50}px; }}\n"  # a figure shown at its own width


#: How each footprint rule reads in the report.
FOOTPRINT_WORDS = {"known": "known cells", "walls": "enclosed by its walls",
                   "seen": "seen by its scans", "all": "its whole rectangle"}


def _img(png: bytes, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,' \
           f'{base64.b64encode(png).decode("ascii")}">'


def _nearest(points: np.ndarray, others: np.ndarray) -> list[str]:
    """Distance, metres, from each of ``points`` (N, 2) to the nearest of ``others`` (M, 2);
    '-' for every point when there is none."""
    return [number(None if np.isnan(d) else d) for d in nearest_distances(points, others)]


def _feature_list(label: str, xy: np.ndarray, others: np.ndarray, other_side: str) -> str:
    """One scrollable table of features: number, x, y, distance to the nearest feature of the
    other side."""
    rows = [[str(i + 1), number(x), number(y), d]
            for i, ((x, y), d) in enumerate(zip(xy.tolist(), _nearest(xy, others),
                                                strict=True))]
    table = _table(["#", "x [m]", "y [m]", f"nearest {other_side} feature [m]"], rows)
    return f'<div><h3>{html.escape(label)}</h3><div class="list">{table}</div></div>'


def _lists(name: str, det: DetectorResult) -> str:
    """The missing truth features and the extra map features of one detector, truth frame."""
    m = det.matching
    return '<div class="lists">' + _feature_list(
        f"{name}: {len(m.missing)} missing (truth features with no map partner)",
        det.truth.xy[m.missing], det.map.xy, "map") + _feature_list(
        f"{name}: {len(m.extra)} extra (map features with no truth partner)",
        det.map.xy[m.extra], det.truth.xy, "truth") + "</div>"


def _table(header: list[str], rows: list[list[str]], breaks: str = "") -> str:
    """A table: ``header`` above ``rows`` (text, escaped); a header may break after any of the
    characters ``breaks`` (long column names such as ``wall_precision@0.1m``)."""
    def name(h: str) -> str:
        text = html.escape(h)
        for c in breaks:
            text = text.replace(c, c + "<wbr>")
        return text

    head = "".join(f"<th>{name(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


#: The statistics a table shows, with their headers.
STATS_COLUMNS = (("mean", "mean [m]"), ("median", "median [m]"), ("rmse", "RMSE [m]"),
                 ("std", "std [m]"), ("min", "min [m]"), ("max", "max [m]"),
                 ("p95", "95th pct [m]"))


def _stats_cells(s: Stats) -> list[str]:
    return [number(getattr(s, key)) for key, _ in STATS_COLUMNS]


def _stats_table(counted: str, rows: list[tuple[str, Stats]]) -> str:
    """A table of distance statistics, one row per (label, stats)."""
    return _table(["", *(h for _, h in STATS_COLUMNS), counted],
                  [[label, *_stats_cells(s), str(s.count)] for label, s in rows])


def _run(result: Result) -> str:
    """How the result was made: pcmapq's version, the command line (when it came from one) and
    every setting it ran with (metres and degrees), as the JSON's ``pcmapq`` and ``settings``
    hold them."""
    command = html.escape(result.command) if result.command else "(called from Python)"
    settings = html.escape(json.dumps(result.settings or {}, indent=1, sort_keys=True,
                                           allow_nan=False))
    return (f"<p>pcmapq {__version__}; command: <code>{command}</code></p>"
            f"<details><summary>settings</summary><pre>{settings}</pre></details>")


def _relief(result: Result) -> str:
    """Two 3D clouds: the 3D consistency map's section (its figures in words, the top view of
    each region's vertical offset and the side profile); '' otherwise."""
    c = result.consistency_3d
    if c is None:
        return ""
    figure = _img(png_bytes(relief_figure(result)),
                  "each region's vertical offset dz: top view and side profile") \
        if has_relief(result) else ""
    cut = ("tiles of the ground" if c.scans is None else
           f"stretches of the run ({c.cut()}: the points each stretch's scans put in the map, "
           "wherever they lie)")
    return (f"<h2>Where the map bends in 3D</h2><p>{html.escape('; '.join(relief_parts(result)))}"
            f"</p>{figure}<p class=\"note\">The map, as the 3D registration placed it, cut into "
            f"{html.escape(cut)}, each registered to the truth on its own in 3D. dz: where the "
            "map has a region, from where it fits the truth (below 0: the map lies too low "
            "there). Held: its geometry pins the fit in every direction and it fits; the "
            f"others are {'hatched' if c.scans is None else 'hollow'} (their offset is not "
            "sure). Truth frame levelled, metres.</p>")


def report_html(result: Result, scale: float | None = None) -> str:
    """The whole report as one HTML document (figures as embedded PNGs, no network needed);
    every arrow, of the interactive map and of the figure, ``scale`` times its length (None:
    :func:`~pcmapq.report.arrows.auto_arrow_scale`)."""
    a, tf, o = result.alignment, result.transform, result.overlap
    inputs = _table(["", "path", "kind"], [
        ["map", str(result.map_path), result.map_kind],
        ["truth", str(result.truth_path),
         f"{result.truth_kind}, {result.grid.resolution:g} m cells, "
         f"{result.grid.size_m[0]:.1f} x {result.grid.size_m[1]:.1f} m"]])
    alignment = _table(
        ["x [m]", "y [m]", "yaw [deg]", "scale", "fitness", "inlier RMSE [m]", "method"],
        [[number(tf.tx), number(tf.ty), number(tf.yaw_deg, 2), number(tf.scale, 4),
          f"{number(a.fitness)} (within {a.tolerance_m:g} m)", number(a.rmse_m), a.method]])
    c = result.consistency
    k = None if c is None else c.largest()
    cover = _table(["coverage", "footprint", "truth recall in footprint", "confidence",
                    "verdict", "largest region offset [m]", "scored against"],
                   [[number(o.coverage), FOOTPRINT_WORDS.get(result.footprint_rule, ""),
                     number(o.truth_recall), number(o.confidence), o.verdict,
                     "-" if k is None else f"{number(c.offset_m[k])} at "
                     f"({c.centre[k][0]:.1f}, {c.centre[k][1]:.1f})",
                     "whole truth" if result.full else "the map's footprint"]])
    rows = []
    for name, det in result.detectors.items():
        m = det.matching
        rows.append([name, score(m.quality), score(m.precision), score(m.f1),
                     str(m.truth_features), str(m.map_features), str(m.matched),
                     str(m.matched_map), *_stats_cells(det.displacement_stats())])
    rows += structures.html_rows(result, _stats_cells)  # beside them: the 3D structures
    scores = _table(["detector", "quality q", "precision", "f1", "truth features",
                     "map features", "truth matched", "map matched",
                     *(f"disp. {h}" for _, h in STATS_COLUMNS)], rows)
    scores += "".join(f'<p class="note">{html.escape(n)}</p>'
                      for n in result.notes() + structures.notes(result))
    if result.structures is not None:
        scores += f'<p class="note">{html.escape(structures.thresholds(result))}.</p>'
    d = result.distances
    dist = _stats_table("cells", [("accuracy (map to truth)", d.accuracy),
                                  ("completeness (truth to map)", d.completeness)])
    fscore = _table(["threshold [m]", "precision", "recall", "F-score"],
                    [[f"{f.tau_m:g}", number(f.precision), number(f.recall), number(f.f)]
                     for f in d.fscores])
    if result.registration_3d is not None and result.distances_3d is not None:
        reg, d3 = result.registration_3d, result.distances_3d
        dist += "<p class=\"note\">Both inputs are 3D clouds: registered in 3D (fitness " \
                f"{number(reg.fitness)}, RMSE {number(reg.rmse_m)} m); distances between the " \
                "clouds:</p>"
        dist += _stats_table("points", [("3D accuracy (map to truth)", d3.accuracy),
                                        ("3D completeness (truth to map)", d3.completeness)])
    if result.map_3d is not None:
        parts = ", ".join(map_3d_parts(result.map_3d, result.settings))
        dist += "<p class=\"note\">MapEval's map figures of the two 3D clouds (lower is " \
                f"better): {html.escape(parts)}.</p>"
    gain = arrow_scale(result, scale)
    viewer = viewer_html(result, gain)
    vectors = _img(png_bytes(vectorial_figure(result, gain, relief=False)),
                   "vectorial map per detector")
    heat = _img(png_bytes(distance_heatmap(result)),
                "distance heatmaps: accuracy (map to truth) and completeness (truth to map)")
    lists = "".join(_lists(name, det) for name, det in result.detectors.items()) + \
        structures.planes_html(result)
    title = f"pcmapq: {html.escape(result.map_path.name)} against " \
            f"{html.escape(result.truth_path.name)}"
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>{STYLE}{VIEWER_STYLE}</style></head><body>
<h1>{title}</h1>
<p class="sub">pcmapq {__version__}. Frame convention: p_truth = s R(yaw) p_map + t; all
coordinates in the truth frame, metres and degrees.</p>
<h2>Inputs</h2>{inputs}
<h2>Alignment (map frame to truth frame)</h2>{alignment}
<p class="note">Fitness: share of map points within the tolerance of a truth wall after
alignment. A low fitness on a map of the right place measures its distortion.</p>
<h2>Coverage</h2>{cover}
<p class="note">Coverage: share of the truth's walls inside the area the map observed (its
footprint). Truth features outside the footprint are not counted as missing.</p>
<h2>Feature matching within {result.threshold:g} m</h2>{scores}
<p class="note">quality q = matched truth features / truth features (the paper's measure, a
recall); precision = matched map features / map features; f1 = their harmonic mean;
n/a: nothing to count (undefined, not 0). Displacements are from each truth feature to its
map feature.</p>
<h2>Distances</h2>{dist}
<p class="note">Chamfer distance {number(d.chamfer_m)} m (mean of the two means). Definitions in
docs/metrics.md.</p>{fscore}
<h2>Interactive map</h2>{viewer}
<h2>Vectorial map</h2>{vectors}
{_relief(result)}<h2>Distance heatmaps</h2>{heat}
<p class="note">Left, accuracy: each wall cell of the aligned map coloured by its distance to
the nearest truth wall. Right, completeness: each truth wall cell the scores count coloured by
its distance to the nearest map wall.</p>
<h2>Missing and extra features</h2>
<p class="note">Truth frame, metres. A feature with a partner within {result.threshold:g} m
is still listed when the one-to-one assignment gave that partner to another feature.</p>{lists}
<h2>Run</h2>{_run(result)}
</body></html>
"""
