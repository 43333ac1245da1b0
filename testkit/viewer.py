"""The report's interactive map checked as a user sees it: the circles a page holds, and a probe
run in headless Chromium that zooms, pans, hovers, clicks and toggles as a user would."""

from __future__ import annotations

import html
import json
import re
import subprocess
from pathlib import Path

import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.features import Features
from pcmapq.match import Matching
from pcmapq.report.canvas import window
from pcmapq.results.result import DetectorResult, Result

CIRCLE = re.compile(r"<circle ([^>]*)/>")
ATTR = re.compile(r'([\w-]+)="([^"]*)"')


def circles(page: str) -> list[dict[str, str]]:
    """The attributes of every circle of ``page``."""
    return [dict(ATTR.findall(c)) for c in CIRCLE.findall(page)]


#: Run in the page after the viewer's script: zoom, pan, hover, click and toggle as a user
#: would (dispatched DOM events), and write what the page shows into <pre id="probe">.
PROBE = """
<script>
(function () {
  const svg = document.getElementById('viewer-svg');
  const tip = document.getElementById('viewer-tip');
  const out = {};
  const box = () => svg.getAttribute('viewBox').split(' ').map(Number);
  const user = (x, y) => {
    const p = new DOMPoint(x, y).matrixTransform(svg.getScreenCTM().inverse());
    return [p.x, p.y];
  };
  const r = svg.getBoundingClientRect();
  const cx = r.left + r.width * 0.3, cy = r.top + r.height * 0.6;
  out.before = box();
  out.under = user(cx, cy);
  svg.dispatchEvent(new WheelEvent('wheel', {deltaY: -500, clientX: cx, clientY: cy,
                                             bubbles: true, cancelable: true}));
  out.zoomed = box();
  out.underAfter = user(cx, cy);
  const px = svg.getScreenCTM().a;
  const ev = (type, x, y) => svg.dispatchEvent(new PointerEvent(type, {clientX: x, clientY: y,
                                                                       bubbles: true}));
  ev('pointerdown', cx, cy); ev('pointermove', cx + 40, cy + 20); ev('pointerup', cx + 40, cy + 20);
  svg.dispatchEvent(new MouseEvent('click', {clientX: cx + 40, clientY: cy + 20, bubbles: true}));
  out.afterPan = getComputedStyle(tip).display;  // the click that ends a drag pins nothing
  out.panned = box();
  out.pxPerUnit = px;
  document.getElementById('viewer-reset').click();
  out.reset = box();
  const f = document.querySelector(FEATURE);
  f.scrollIntoView({block: 'center'});
  const fr = f.getBoundingClientRect();
  const fx = fr.left + fr.width / 2, fy = fr.top + fr.height / 2;
  out.hit = document.elementFromPoint(fx, fy) === f;
  out.radiusPx = fr.width / 2;
  f.dispatchEvent(new MouseEvent('mouseover', {clientX: fx, clientY: fy, bubbles: true}));
  out.hover = tip.textContent;
  out.hoverShown = getComputedStyle(tip).display;
  f.dispatchEvent(new MouseEvent('mouseout', {clientX: fx, clientY: fy, bubbles: true}));
  out.afterOut = getComputedStyle(tip).display;
  f.dispatchEvent(new MouseEvent('click', {clientX: fx, clientY: fy, bubbles: true}));
  out.clicked = tip.textContent;
  out.pinnedShown = getComputedStyle(tip).display;
  const visible = (sel) => Array.from(document.querySelectorAll(sel))
    .map((c) => c.getBoundingClientRect().width > 0);  // 0 when not rendered
  const [name, status] = TOGGLE;
  const group = `circle[data-detector="${name}"][data-status="${status}"]`;
  out.toggledBefore = visible(group);
  document.querySelector(`input[data-layer="f-${name}-${status}"]`).click();
  out.toggledAfter = visible(group);
  out.othersAfter = visible(`circle:not([data-detector="${name}"]), ` +
                            `circle[data-detector="${name}"]:not([data-status="${status}"])`);
  const pre = document.createElement('pre');
  pre.id = 'probe';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
})();
</script>
"""


def chromium(path: Path, tmp_path: Path, width: int = 1400, height: int = 1000,
             *flags: str) -> subprocess.CompletedProcess:
    """Headless Chromium run on the page at ``path`` in a ``width`` x ``height`` px window,
    with a profile of its own under ``tmp_path`` and nothing beside the page (no network, no
    sync); ``flags``: what it is to do (``--dump-dom``, ``--screenshot=FILE``, ...)."""
    return subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu",
                           "--disable-quic", "--no-first-run", "--disable-background-networking",
                           "--disable-component-update", "--disable-sync",
                           f"--user-data-dir={tmp_path / 'profile'}",
                           f"--window-size={width},{height}", *flags, path.as_uri()],
                          capture_output=True, timeout=120, check=True, text=True)


def probe_of(run: subprocess.CompletedProcess) -> dict:
    """The JSON a page's script wrote into ``<pre id="probe">``, from Chromium's dumped DOM."""
    probe = re.search(r'<pre id="probe">(.*?)</pre>', run.stdout, re.S)
    assert probe, run.stderr[-2000:]
    return json.loads(html.unescape(probe.group(1)))


def probed(page: str, feature: str, toggle: tuple[str, str], tmp_path: Path) -> dict:
    """What PROBE found in ``page`` (HTML) in headless Chromium, hovering and clicking the
    circle ``feature`` (a CSS selector) and unticking the ``toggle`` (detector, status)."""
    path = tmp_path / "page.html"
    path.write_text(page.replace("</body>", PROBE.replace("FEATURE", json.dumps(feature))
                                 .replace("TOGGLE", json.dumps(toggle)) + "</body>"))
    return probe_of(chromium(path, tmp_path, 1400, 1000, "--dump-dom"))


def check_view(out: dict, result: Result) -> None:
    """The view before (the part of the grid that holds walls), zoomed 2.1-fold about the
    cursor, then panned by the pointer's 40, 20 pixels, reset; the feature on top where it is
    drawn, 4 pixels in radius."""
    before, zoomed, panned = (np.array(out[k]) for k in ("before", "zoomed", "panned"))
    rows, cols = window(result)
    np.testing.assert_allclose(before, [cols.start - 0.5, rows.start - 0.5,
                                        cols.stop - cols.start, rows.stop - rows.start])
    np.testing.assert_allclose(zoomed[2:], before[2:] * 1.0015 ** -500, rtol=1e-6)
    step = 1 / out["pxPerUnit"]  # one screen pixel, grid cells
    np.testing.assert_allclose(out["underAfter"], out["under"], atol=step)
    np.testing.assert_allclose(panned, zoomed - [40 * step, 20 * step, 0, 0], atol=1e-6)
    np.testing.assert_allclose(out["reset"], before)
    assert out["hit"] and 3.5 <= out["radiusPx"] <= 4.5
    assert (out["afterPan"], out["hoverShown"], out["afterOut"], out["pinnedShown"]) == \
        ("none", "block", "none", "block")


def selector(name: str, status: str, x: float, y: float) -> str:
    return f'circle[data-detector="{name}"][data-status="{status}"][data-x="{x + 0.0:.3f}"]' \
           f'[data-y="{y + 0.0:.3f}"]'


def detector_result(truth_xy, map_xy, pairs, displacement, missing, extra,
                    segments=None) -> DetectorResult:
    """A hand-made detector result: truth and map features (metres), the matched pairs
    (truth indices, map indices) with their displacements, the missing truth and extra map
    features (indices); Hough's ``segments`` when given. Only what the viewer reads is set."""
    n, k = len(truth_xy), len(map_xy)
    m = Matching(np.array(pairs[0], dtype=np.intp), np.array(pairs[1], dtype=np.intp),
                 np.array(displacement, dtype=float).reshape(-1, 2), np.zeros(len(pairs[0])),
                 None, None, None, n, k, len(pairs[0]), len(pairs[0]),
                 np.array(missing, dtype=np.intp), np.array(extra, dtype=np.intp))
    return DetectorResult(
        Features(np.array(truth_xy, float).reshape(-1, 2), np.ones(n), np.ones(n, bool),
                 segments=segments),
        Features(np.array(map_xy, float).reshape(-1, 2), np.ones(k), np.ones(k, bool)), m)


def small_result(grid: MetricGrid) -> Result:
    """A hand-made result on ``grid``: harris with 1 matched (0.3, -0.4 m: 0.5 m), 2 missing,
    1 extra; hough with one matched segment; sift with no feature. Only what the viewer reads
    is set."""
    harris = detector_result([[2.0, 3.0], [4.0, 5.0], [6.0, 2.5]], [[2.3, 2.6], [5.0, 3.0]],
                             ([0], [0]), [[0.3, -0.4]], [1, 2], [1])
    hough = detector_result([[3.0, 4.0]], [[3.0, 4.1]], ([0], [0]), [[0.0, 0.1]], [], [],
                            segments=np.array([[2.0, 4.0, 4.0, 4.0]]))
    sift = detector_result(np.zeros((0, 2)), np.zeros((0, 2)), ([], []), [], [], [])
    walls = np.zeros(grid.shape, bool)
    walls[5, :] = True
    return Result(map_path=None, map_kind="", truth_path=None, truth_kind="", grid=grid,
                  alignment=None, overlap=None, distances=None, registration_3d=None,
                  distances_3d=None, threshold=0.5, full=True,
                  detectors={"harris": harris, "hough": hough, "sift": sift},
                  truth_occupied=walls, map_occupied=np.roll(walls, 2, axis=0), frames=None)


#: A grid turned by 30 degrees, off the origin: the features must follow the grid.
TURNED = MetricGrid(0.1, (1.0, 2.0, float(np.radians(30.0))), (60, 80))
