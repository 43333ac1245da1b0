"""track.html in a window 1400 px wide (and a narrower one) in headless Chromium: no page wider
than the window, every column of the steps table reachable, figures scaled to the width."""

from __future__ import annotations

import shutil
from dataclasses import asdict

import pytest

from pcmapq.report.plot import png_bytes
from pcmapq.report.timeline import TABLE, timeline_figure, timeline_html
from pcmapq.track.drop import worst_drop
from pcmapq.track.outputs import step_rows
from pcmapq.track.timeline import Step
from testkit.viewer import chromium, probe_of

#: A path with no place to break: longer than the window.
LONG = "/data/" + "run_" * 60 + "final.log.gz"


def widest_page() -> str:
    """track.html of 12 steps with every column of the steps table (reference poses given: the
    widest table), a drop in precision at step 6 (its marks in the step column), the curves
    drawn, a long unbroken path among the inputs and in the command."""
    figures = [c for c in TABLE if c not in ("step", "scans", "distance_m")]
    precision = [0.9, 0.91, 0.92, 0.93, 0.93, 0.93, 0.8, 0.7, 0.65, 0.66, 0.66, 0.66]
    steps = [Step(i, 50 * (i + 1), None, 40.0 * i + 0.5,
                  {c: (p if c == "precision" else 0.5 + 0.04 * i) for c in figures}, "")
             for i, p in enumerate(precision)]
    rows, drop = step_rows(steps), asdict(worst_drop(steps))
    return timeline_html(rows, drop, drop["start"], None, None,
                         command=f"pcmapq track {LONG} t.png",
                         inputs={"run": LONG, "poses": "the log's own FLASER poses",
                                 "truth": "t.png", "reference poses": LONG},
                         curves=png_bytes(timeline_figure(rows, drop)))


#: After load: the page's and the steps box's widths, where the last column's header ends once
#: the box is scrolled to its end, and each figure's width against its container's.
PROBE = """
<script>
window.addEventListener('load', function () {
  const root = document.documentElement;
  const box = document.querySelector('.steps');
  const out = {page: root.scrollWidth, window: root.clientWidth, boxScroll: box.scrollWidth,
               boxWidth: box.clientWidth, overflow: getComputedStyle(box).overflowX,
               columns: box.querySelectorAll('tr:first-child th').length};
  box.scrollLeft = box.scrollWidth;
  const last = box.querySelector('tr:first-child th:last-child').getBoundingClientRect();
  out.lastLeft = last.left;
  out.lastRight = last.right;
  out.figures = Array.from(document.images).map((i) => [i.getBoundingClientRect().width,
                                                        i.parentNode.clientWidth]);
  const pre = document.createElement('pre');
  pre.id = 'probe';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>
"""


def probed(page: str, width: int, tmp_path) -> dict:
    """What PROBE found in ``page`` (HTML) in headless Chromium, ``width`` x 1000 px."""
    path = tmp_path / f"track-{width}.html"
    path.write_text(page.replace("</body>", PROBE + "</body>"))
    return probe_of(chromium(path, tmp_path, width, 1000, "--dump-dom"))


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Debian's chromium is not installed")
def test_track_report_fits_the_window_in_chromium(tmp_path):
    """At 1400 px the page is no wider than the window (it was 1748 px with reference poses)
    and the steps table fits whole, its column names broken at '_' and '@'; at 900 px the page
    still fits, the table scrolls inside its own box and its last column is reached by
    scrolling that box; the curves (1350 px drawn) shrink to the page."""
    page = widest_page()
    for width in (1400, 900):
        out = probed(page, width, tmp_path)
        assert out["columns"] == len(TABLE)
        assert out["page"] <= out["window"] < width, (width, out)
        assert out["overflow"] == "auto"
        assert 0 <= out["lastLeft"] < out["lastRight"] <= out["window"], (width, out)
        assert out["figures"] and all(w <= room + 0.5 for w, room in out["figures"]), out
        if width == 1400:
            assert out["boxScroll"] <= out["boxWidth"], out
        else:
            assert out["boxScroll"] > out["boxWidth"], out
