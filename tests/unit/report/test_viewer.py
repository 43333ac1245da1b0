"""The report's interactive map: every feature in it with its data, placed where the grid puts
it (in headless Chromium: tests/e2e/test_viewer_chromium.py)."""
from __future__ import annotations

import base64
import re

import cv2
import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.report.viewer import VIEWER_PX, viewer_html
from pcmapq.testing.viewer import TURNED, circles, small_result


def test_viewer_places_each_feature_where_the_grid_puts_it():
    """One circle per feature, at its grid cell (u, v), with its metric x, y, detector, status
    and displacement; nearest other-side feature for the unmatched."""
    page = viewer_html(small_result(TURNED), 10.0)
    got = circles(page)
    assert len(got) == 5
    for c in got:
        uv = TURNED.xy_to_pixels([[float(c["data-x"]), float(c["data-y"])]])[0]
        np.testing.assert_allclose([float(c["cx"]), float(c["cy"])], uv, atol=0.006)
    by = {(c["data-detector"], c["data-status"], c["data-x"], c["data-y"]): c for c in got}
    matched = by[("harris", "matched", "2.000", "3.000")]
    assert (matched["data-displacement"], matched["data-dx"], matched["data-dy"],
            matched["data-map-x"], matched["data-map-y"]) == ("0.500", "0.300", "-0.400",
                                                              "2.300", "2.600")
    assert by[("harris", "missing", "4.000", "5.000")]["data-nearest"] == f"{np.hypot(1, 2):.3f}"
    assert by[("harris", "extra", "5.000", "3.000")]["data-nearest"] == f"{np.hypot(1, 0.5):.3f}"
    assert "data-displacement" not in by[("harris", "missing", "6.000", "2.500")]
    assert ("hough", "matched", "3.000", "4.000") in by
    # the matched arrow runs 10 times the displacement from the truth feature
    u, v = TURNED.xy_to_pixels([[2.0, 3.0], [2.0 + 3.0, 3.0 - 4.0]])
    assert f'<line class="arrow" x1="{u[0]:.2f}" y1="{u[1]:.2f}" x2="{v[0]:.2f}" ' \
           f'y2="{v[1]:.2f}"/>' in page
    assert page.count('class="segment"') == 1
    for name in ("harris", "hough", "sift"):
        for status in ("matched", "missing", "extra"):
            assert f'<g id="f-{name}-{status}">' in page
            assert f'data-layer="f-{name}-{status}"' in page


def test_viewer_pools_large_grids_and_is_deterministic():
    """A grid larger than VIEWER_PX is pooled to at most VIEWER_PX pixels a side, drawn over
    the grid's whole extent; the same result gives the same bytes."""
    grid = MetricGrid(0.01, (0.0, 0.0, 0.0), (3000, 5000))
    result = small_result(grid)
    page = viewer_html(result, 10.0)
    assert page == viewer_html(small_result(grid), 10.0)
    factor = -(-5000 // VIEWER_PX)
    assert f"(here {factor} x {factor}\ncells a pixel)" in page
    sizes = re.findall(r'<image x="-0.5" y="-0.5" width="(\d+)" height="(\d+)"', page)
    assert sizes == [(str(-(-5000 // factor) * factor), str(-(-3000 // factor) * factor))] * 2
    for uri in re.findall(r'href="data:image/png;base64,([^"]+)"', page):
        img = cv2.imdecode(np.frombuffer(base64.b64decode(uri), np.uint8), cv2.IMREAD_UNCHANGED)
        assert img.shape == (-(-3000 // factor), -(-5000 // factor), 4)
        assert max(img.shape[:2]) <= VIEWER_PX and img[..., 3].any()
