"""The report's interactive map of a whole evaluation: one element per feature and nothing from a
network; in headless Chromium, the moved wall's displacement told and its features toggled."""

from __future__ import annotations

import re
import shutil

import numpy as np
import pytest

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.html import report_html
from pcmapq.settings import MatchingConfig, Settings
from testkit import synth
from testkit.files import write_image_map
from testkit.viewer import check_view, circles, probed, selector

CHROMIUM = pytest.mark.skipif(shutil.which("chromium") is None,
                              reason="Debian's chromium is not installed")


@pytest.fixture(scope="module")
def moved_result(plan, truth_png, tmp_path_factory):
    """test_report's map whose L-shaped wall stands 0.5 m east of the truth's."""
    moved = synth.move_wall(synth.move_wall(plan, 20, (0.5, 0.0)), 21, (0.5, 0.0))
    path = write_image_map(moved, tmp_path_factory.mktemp("moved") / "moved.png")
    return evaluate(path, truth_png, Settings(matching=MatchingConfig(threshold=1.0)))


def test_report_holds_one_element_per_feature_and_nothing_from_a_network(moved_result):
    """The report's viewer: no script, style or picture fetched (no http(s) src or href), and
    one circle per matched, missing and extra feature of each detector."""
    page = report_html(moved_result)
    assert not re.search(r'(src|href)\s*=\s*["\']?(https?:)?//', page, re.I)
    assert "<script>" in page and "<script src" not in page
    got = circles(page)
    for name, det in moved_result.detectors.items():
        m = det.matching
        for status, n in (("matched", len(m.truth_idx)), ("missing", len(m.missing)),
                          ("extra", len(m.extra))):
            mine = [c for c in got if (c["data-detector"], c["data-status"]) == (name, status)]
            assert len(mine) == n, (name, status)
        shown = sorted(float(c["data-displacement"]) for c in got
                       if (c["data-detector"], c["data-status"]) == (name, "matched"))
        np.testing.assert_allclose(shown, np.sort(det.distances), atol=5e-4)
    assert len(got) == sum(len(d.matching.truth_idx) + len(d.matching.missing)
                           + len(d.matching.extra) for d in moved_result.detectors.values())


@CHROMIUM
def test_report_viewer_tells_the_moved_walls_displacement_in_chromium(moved_result, tmp_path):
    """The whole report: the moved wall's Hough feature tells its 0.5 m displacement; unticking
    hough's matched hides all 22 of them and no other feature."""
    det = moved_result.detectors["hough"]
    i = int(np.argmax(det.distances))
    (x, y), d = det.truth_xy[i], det.distances[i]
    assert d > 0.49  # the wall moved by 0.5 m
    out = probed(report_html(moved_result), selector("hough", "matched", x, y),
                 ("hough", "matched"), tmp_path)
    check_view(out, moved_result)
    for text in (out["hover"], out["clicked"]):
        assert text.startswith(f"hough: matched\nx {x + 0.0:.3f} m, y {y + 0.0:.3f} m\n")
        assert f"displacement {d:.3f} m" in text
    n = len(det.matching.truth_idx)
    assert (out["toggledBefore"], out["toggledAfter"]) == ([True] * n, [False] * n)
    others = sum(len(v.matching.truth_idx) + len(v.matching.missing) + len(v.matching.extra)
                 for v in moved_result.detectors.values()) - n
    assert out["othersAfter"] == [True] * others
