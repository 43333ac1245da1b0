"""The report's interactive map: truth and aligned map overlaid in an inline SVG that zooms
(wheel) and pans (drag), every feature a circle that tells, hovered or clicked, its detector,
whether it is matched, missing or extra, where it stands and its displacement, metres.

The SVG's user unit is one cell of the truth grid (cell centres at integers, as
:meth:`~pcmapq.core.grid.MetricGrid.xy_to_pixels` gives them), so the walls, drawn in the grid's own
rows and columns, and the features, placed from their metric (truth frame) coordinates, stand
where the grid puts them for any grid origin and yaw. The walls are two embedded PNGs (the
truth dark over the aligned map light, as in the figures) of the part of the grid that holds
walls (:func:`~pcmapq.report.canvas.window`, where the view opens), pooled to at most
:data:`VIEWER_PX` pixels across and down (:mod:`pcmapq.raster.pool`), so a map of any size
costs pictures of bounded size; every feature is kept, none thinned. One ``<g>`` per detector
and status holds its circles (Hough: its segments too; matched: the displacement arrows), and a
checkbox shows or hides it. Markers keep their size on screen while the walls scale with the
zoom, so where the markers crowd over thin walls (a street map seen whole) the walls are drawn
over them and the features as rings (:data:`CROWDED_PX`, :data:`SMALL_CELL_PX`); zoomed in,
the features are drawn over the walls. No network: the script is inline and plain
JavaScript.
"""

from __future__ import annotations

import base64
import html
import json

import cv2
import numpy as np
from scipy.spatial import cKDTree

from pcmapq.report.canvas import density, grown, shade, window
from pcmapq.report.style import MAP_LIGHT, TRUTH_DARK
from pcmapq.report.viewer_page import COLOURS, SCRIPT, STATUSES
from pcmapq.results.result import DetectorResult, Result

#: Longest side, pixels, of the embedded wall pictures: sharp on a 1350-pixel-wide viewer
#: zoomed in 1.5-fold, and a few hundred kB on the largest maps.
VIEWER_PX = 2048
#: Opacity of the truth's walls over the map's (canvas.TRUTH_ALPHA).
TRUTH_OPACITY = 0.9
def _png(alpha: np.ndarray, rgb: tuple[float, float, float], opacity: float) -> str:
    """A data URI of an RGBA PNG: ``rgb`` (0-1) at ``opacity`` times ``alpha`` (rows, cols,
    [0, 1]) per pixel."""
    rgba = np.empty((*alpha.shape, 4), np.uint8)
    rgba[..., :3] = np.round(np.asarray(rgb[::-1]) * 255)  # OpenCV writes BGR(A)
    rgba[..., 3] = np.round(np.clip(alpha, 0.0, 1.0) * opacity * 255)
    ok, buf = cv2.imencode(".png", rgba)
    if not ok:
        raise ValueError("PNG encoding failed")
    return "data:image/png;base64," + base64.b64encode(buf.tobytes()).decode("ascii")


def nearest_distances(points: np.ndarray, others: np.ndarray) -> np.ndarray:
    """Distance, metres, from each of ``points`` (N, 2) to the nearest of ``others`` (M, 2):
    (N,) float, NaN when there is no other."""
    if len(others) == 0 or len(points) == 0:
        return np.full(len(points), np.nan)
    return cKDTree(others).query(points)[0]


def _mm(value: float) -> str:
    return f"{value + 0.0:.3f}"


def _uv(result: Result, xy: np.ndarray) -> np.ndarray:
    """Metric (N, 2) -> the SVG's user units (grid cells), (N, 2)."""
    return result.grid.xy_to_pixels(xy) if len(xy) else np.zeros((0, 2))


def _circles(result: Result, name: str, status: str, xy: np.ndarray,
             extra: list[dict[str, str]]) -> str:
    """One circle per feature at ``xy`` (N, 2, metres) with its data attributes, and the
    per-feature ``extra`` ones."""
    out = []
    for (u, v), (x, y), attrs in zip(_uv(result, xy).tolist(), xy.tolist(), extra, strict=True):
        more = "".join(f' data-{k}="{val}"' for k, val in attrs.items())
        out.append(f'<circle cx="{u:.2f}" cy="{v:.2f}" data-detector="{name}" '
                   f'data-status="{status}" data-x="{_mm(x)}" '
                   f'data-y="{_mm(y)}"{more}/>')
    return "".join(out)


def _lines(result: Result, starts: np.ndarray, ends: np.ndarray, cls: str) -> str:
    """Lines from ``starts`` to ``ends`` (N, 2, metres) of class ``cls``."""
    if len(starts) == 0:
        return ""
    return "".join(f'<line class="{cls}" x1="{a:.2f}" y1="{b:.2f}" x2="{c:.2f}" y2="{d:.2f}"/>'
                   for (a, b), (c, d) in zip(_uv(result, starts).tolist(),
                                             _uv(result, ends).tolist(), strict=True))


def _segments(result: Result, segments: np.ndarray | None, idx: np.ndarray) -> str:
    """Hough's segments ``idx`` (x0, y0, x1, y1 metres), none for a point detector."""
    if segments is None:
        return ""
    picked = segments[idx].reshape(-1, 4)
    return _lines(result, picked[:, :2], picked[:, 2:], "segment")


def _groups(result: Result, name: str, det: DetectorResult, gain: float) -> dict[str, str]:
    """The SVG of each status of one detector: its segments, arrows and circles."""
    m = det.matching
    disp = m.displacement
    matched = [{"map-x": _mm(px), "map-y": _mm(py), "dx": _mm(dx), "dy": _mm(dy),
                "displacement": _mm(d)}
               for (px, py), (dx, dy), d in zip(det.map_xy.tolist(), disp.tolist(),
                                                 det.distances.tolist(), strict=True)]
    missing, extra = det.truth.xy[m.missing], det.map.xy[m.extra]
    # the rooms' table is in the features' order in a result scored here (not one read back
    # from JSON, whose features are rebuilt from its lists)
    rooms = result.rooms if name == "rooms" and det.truth.labels is not None else None

    def room(side: str, k: int) -> dict[str, str]:
        """A room's line of the tooltip: its number, area, status and, matched, its fit."""
        if rooms is None:
            return {}
        r = rooms[side][k]
        text = f"{side} room {k}: {r['area_m2']:.2f} m2, {r['status']}"
        if "iou" in r:
            text += (f"; IoU {r['iou']:.3f}, area error {r['area_error_m2']:+.2f} m2, "
                     f"offset {r['offset_m']:.3f} m")
        return {"room": html.escape(text)}

    matched = [{**row, **room("truth", int(k))} for row, k in zip(matched, m.truth_idx,
                                                                 strict=True)]

    def near(d: float) -> dict[str, str]:
        return {"nearest": "" if np.isnan(d) else _mm(d)}

    return {
        "matched": _segments(result, det.truth.segments, m.truth_idx)
        + _lines(result, det.truth_xy, det.truth_xy + gain * disp, "arrow")
        + _circles(result, name, "matched", det.truth_xy, matched),
        "missing": _segments(result, det.truth.segments, m.missing)
        + _circles(result, name, "missing", missing,
                   [{**near(d), **room("truth", int(k))} for d, k in
                    zip(nearest_distances(missing, det.map.xy), m.missing, strict=True)]),
        "extra": _segments(result, det.map.segments, m.extra)
        + _circles(result, name, "extra", extra,
                   [{**near(d), **room("map", int(k))} for d, k in
                    zip(nearest_distances(extra, det.truth.xy), m.extra, strict=True)]),
    }


def spacing(result: Result) -> float:
    """Median distance, grid cells, from each feature the viewer draws (every detector and
    status) to its nearest other one; infinite when there are fewer than two."""
    xy = [np.vstack([d.truth_xy, d.truth.xy[d.matching.missing], d.map.xy[d.matching.extra]])
          for d in result.detectors.values()]
    uv = _uv(result, np.vstack(xy)) if xy else np.zeros((0, 2))
    if len(uv) < 2:
        return float("inf")
    return float(np.median(cKDTree(uv).query(uv, k=2)[0][:, 1]))


def _controls(result: Result) -> str:
    """Checkboxes: the two wall layers, and each detector's matched, missing, extra groups
    (with their counts)."""
    rows = []
    for name, det in result.detectors.items():
        m = det.matching
        counts = {"matched": len(m.truth_idx), "missing": len(m.missing),
                  "extra": len(m.extra)}
        cells = "".join(
            f'<td><label><input type="checkbox" checked data-layer="f-{name}-{status}"> '
            f'<span style="color:{COLOURS[status]}">&#9679;</span> {html.escape(label)}: '
            f'{counts[status]}</label></td>' for status, label in STATUSES.items())
        rows.append(f"<tr><th>{html.escape(name)}</th>{cells}</tr>")
    walls = "".join(f'<label><input type="checkbox" checked data-layer="{layer}"> {label}'
                    '</label> ' for layer, label in (("walls-truth", "truth walls (dark)"),
                                                     ("walls-map", "aligned map walls (light)")))
    return f'<div class="controls">{walls}<button id="viewer-reset" type="button">' \
           f'reset view</button><table>{"".join(rows)}</table></div>'


def viewer_html(result: Result, arrow_scale: float) -> str:
    """The interactive map as an HTML fragment (its style, controls, SVG and script inline);
    matched features' arrows ``arrow_scale`` times their displacement."""
    shown = window(result)  # every wall lies in it: the first view, and the walls drawn
    shown_rows, shown_cols = shown
    across, down = shown_cols.stop - shown_cols.start, shown_rows.stop - shown_rows.start
    factor = max(1, -(-max(across, down) // VIEWER_PX))
    as_density = density(result)
    truth = shade(result.truth_occupied[shown], factor, as_density)
    walls = grown(shade(result.map_occupied[shown], factor, as_density))
    w, h = walls.shape[1] * factor, walls.shape[0] * factor
    images = "".join(
        f'<g id="{layer}"><image x="{shown_cols.start - 0.5:g}" y="{shown_rows.start - 0.5:g}" '
        f'width="{w}" height="{h}" '
        f'preserveAspectRatio="none" href="{_png(alpha, rgb, opacity)}"/></g>'
        for layer, alpha, rgb, opacity in (("walls-map", walls, MAP_LIGHT, 1.0),
                                           ("walls-truth", truth, TRUTH_DARK, TRUTH_OPACITY)))
    gap = min(spacing(result), 1e9)
    groups = "".join(f'<g id="f-{name}-{status}">{svg}</g>'
                     for name, det in result.detectors.items()
                     for status, svg in _groups(result, name, det, arrow_scale).items())
    return f"""{_controls(result)}
<div class="viewer"><svg id="viewer-svg"
 viewBox="{shown_cols.start - 0.5:g} {shown_rows.start - 0.5:g} {across} {down}"
 style="aspect-ratio: {across} / {down}" data-spacing="{gap:.3f}"
 data-labels="{html.escape(json.dumps(STATUSES))}">
{images}{groups}</svg>
<div id="viewer-tip"></div></div>
<p class="note">Wheel: zoom; drag: pan; hover or click a feature: its detector, match, position
and displacement (truth frame, metres). Arrows: {arrow_scale:g} times the displacement, from
the truth feature to the map feature (the map's error); rings: missing truth features
(red) and extra map features (orange). Walls shown at up to {VIEWER_PX} px (here {factor} x {factor}
cells a pixel); every feature is shown. Where the features crowd over thin walls (zoomed out),
the walls are drawn over them and every feature as a ring; zoom in to draw them over the
walls.</p>
<script>{SCRIPT}</script>"""
