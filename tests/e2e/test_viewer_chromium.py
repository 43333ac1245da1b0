"""The report's interactive map in headless Chromium, as a user sees it: zoom, pan, tooltips and
toggles on a hand-made result, and walls that show through crowded features."""

from __future__ import annotations

import json
import shutil

import cv2
import numpy as np
import pytest

from pcmapq.report.viewer import viewer_html
from pcmapq.report.viewer_page import STYLE
from pcmapq.results.result import Result
from testkit import synth
from testkit.viewer import (
    TURNED,
    check_view,
    chromium,
    detector_result,
    probe_of,
    probed,
    selector,
    small_result,
)

CHROMIUM = pytest.mark.skipif(shutil.which("chromium") is None,
                              reason="Debian's chromium is not installed")


@CHROMIUM
def test_viewer_zooms_pans_tells_and_toggles_in_chromium(tmp_path):
    """The hand-made result on the turned grid: zoom about the cursor, pan, the matched harris
    feature's tooltip (detector, status, both positions, displacement) on hover and click,
    unticking harris' missing hides its two features and nothing else."""
    page = f"<!DOCTYPE html><html><head><style>{STYLE}</style></head><body>" \
           f"{viewer_html(small_result(TURNED), 10.0)}</body></html>"
    out = probed(page, selector("harris", "matched", 2.0, 3.0), ("harris", "missing"), tmp_path)
    check_view(out, small_result(TURNED))
    for text in (out["hover"], out["clicked"]):
        assert text == "harris: matched\nx 2.000 m, y 3.000 m\nmap feature: x 2.300 m, " \
                       "y 2.600 m\ndisplacement 0.500 m (dx 0.300, dy -0.400 m)"
    assert (out["toggledBefore"], out["toggledAfter"]) == ([True] * 2, [False] * 2)
    assert out["othersAfter"] == [True] * 3


def dense_result() -> Result:
    """Two buildings side by side (52 x 16 m, 0.05 m cells, 1081 cells across: 1.3 screen
    pixels a cell at 1400 px) with a feature every 0.2 m along every wall (1.0 m on screen: the
    circles overlap), by turns matched (0.1 m east), missing and extra; Hough's segments are the
    walls themselves. The map's walls stand 0.1 m east of the truth's."""
    plan = synth.campus(2, 1)
    grid = synth.plan_grid(plan, 0.05)
    pieces = synth.densify(plan, 0.2)
    xy = np.unique(np.round(np.vstack([pieces[:, :2], pieces[:, 2:]]), 3), axis=0)
    matched, missing, extra = xy[0::3], xy[1::3], xy[2::3] + [0.05, 0.05]
    shift = np.array([0.1, 0.0])
    n, k = len(matched), len(missing)
    points = detector_result(np.vstack([matched, missing]), np.vstack([matched + shift, extra]),
                             (np.arange(n), np.arange(n)), np.tile(shift, (n, 1)),
                             np.arange(n, n + k), np.arange(n, n + len(extra)))
    middles = (plan[:, :2] + plan[:, 2:]) / 2
    pairs = (np.arange(len(plan)), np.arange(len(plan)))
    hough = detector_result(middles, middles + shift, pairs, np.tile(shift, (len(plan), 1)), [],
                            [], segments=plan)
    walls = synth.render(plan, grid) == synth.OCCUPIED
    moved = synth.render(plan + np.tile(shift, 2), grid) == synth.OCCUPIED
    return Result(map_path=None, map_kind="", truth_path=None, truth_kind="", grid=grid,
                  alignment=None, overlap=None, distances=None, registration_3d=None,
                  distances_3d=None, threshold=0.5, full=True,
                  detectors={"harris": points, "hough": hough}, truth_occupied=walls,
                  map_occupied=moved, frames=None)


#: Shows or hides the walls and the features, then writes into <pre id="probe"> what the view
#: draws over what: at the default view, zoomed in 9.5-fold about the centre, and reset.
LAYERS = """
<script>
(function () {
  const svg = document.getElementById('viewer-svg');
  const hide = (sel) => document.querySelectorAll(sel).forEach((g) => g.setAttribute('display',
                                                                                     'none'));
  if (!WALLS) hide('#walls-map, #walls-truth');
  if (!FEATURES) hide('g[id^="f-"]');
  const order = () => Array.from(svg.children).map((g) => g.id);
  const state = () => ({crowded: svg.classList.contains('crowded'), order: order(),
                        pxPerCell: svg.getScreenCTM().a});
  const c = document.querySelector('circle');
  const r = c.getBoundingClientRect();
  const out = {home: state(), radiusPx: r.width / 2,
               hit: document.elementFromPoint(r.left + r.width / 2,
                                              r.top + r.height / 2).tagName};
  if (PROBE) {
    const s = svg.getBoundingClientRect();
    svg.dispatchEvent(new WheelEvent('wheel', {deltaY: -1500, clientX: s.left + s.width / 2,
                                               clientY: s.top + s.height / 2, bubbles: true,
                                               cancelable: true}));
    out.zoomed = state();
    document.getElementById('viewer-reset').click();
    out.reset = state();
    const pre = document.createElement('pre');
    pre.id = 'probe';
    pre.textContent = JSON.stringify(out);
    document.body.appendChild(pre);
  }
})();
</script>
"""


def rendered(page: str, tmp_path, name: str, walls: bool, features: bool,
             probe: bool = False) -> np.ndarray | dict:
    """``page`` in headless Chromium at 1400 x 1000 px with the walls and features shown or
    hidden: its screenshot (rows, cols, 3) int BGR, or with ``probe`` what LAYERS found."""
    path = tmp_path / f"{name}.html"
    flags = {"WALLS": walls, "FEATURES": features, "PROBE": probe}
    script = LAYERS
    for key, value in flags.items():
        script = script.replace(key, json.dumps(value))
    path.write_text(page.replace("</body>", script + "</body>"))
    shot = tmp_path / f"{name}.png"
    run = chromium(path, tmp_path, 1400, 1000, "--hide-scrollbars",
                   "--dump-dom" if probe else f"--screenshot={shot}")
    if probe:
        return probe_of(run)
    img = cv2.imread(str(shot))
    assert img is not None and img.shape == (1000, 1400, 3)
    return img.astype(int)


def changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pixels where two screenshots differ by more than 40 levels in a channel."""
    return np.abs(a - b).max(axis=2) > 40


@CHROMIUM
def test_walls_show_through_crowded_features_in_chromium(tmp_path):
    """At the default view of a dense map (circles overlapping along walls 4 pixels wide, Hough
    segments on the walls) the walls are drawn over the features, which are rings: at least 95%
    of the pixels the walls paint still change where the features are drawn too (18% when the
    features were drawn over them, filled), and the features still change at least 30% of theirs
    (their rings either side of the walls); a circle under a wall still answers the pointer.
    Zoomed in until the circles part, the features are drawn over the walls again; reset, under
    them."""
    page = f"<!DOCTYPE html><html><head><style>{STYLE}</style></head>" \
           f"<body style='margin: 0'>{viewer_html(dense_result(), 10.0)}</body></html>"
    out = rendered(page, tmp_path, "probe", True, True, probe=True)
    blank, walls, features, both = (rendered(page, tmp_path, f"{w}{f}", w, f)
                                    for w, f in ((0, 0), (1, 0), (0, 1), (1, 1)))
    painted, marked = changed(walls, blank), changed(features, blank)
    assert painted.sum() > 20000 and marked.sum() > 20000
    shown = np.count_nonzero(changed(both, features) & painted) / np.count_nonzero(painted)
    kept = np.count_nonzero(changed(both, walls) & marked) / np.count_nonzero(marked)
    assert shown >= 0.95 and kept >= 0.3, (shown, kept)
    home, zoomed = out["home"], out["zoomed"]
    assert home["pxPerCell"] < 2 and home["crowded"] and out["hit"] == "circle"
    assert 3.5 <= out["radiusPx"] <= 4.5
    assert home["order"][-2:] == ["walls-map", "walls-truth"]
    assert not zoomed["crowded"] and zoomed["order"][:2] == ["walls-map", "walls-truth"]
    assert out["reset"] == home
