"""The report's interactive map: every feature in it with its data, placed where the grid puts
it (in headless Chromium: tests/e2e/test_viewer_chromium.py)."""
from __future__ import annotations

import base64
import re
from dataclasses import replace

import cv2
import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.report.viewer import VIEWER_PX, viewer_html
from testkit.viewer import TURNED, circles, small_result


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


def test_viewer_draws_the_walls_window_of_a_sparse_grid():
    """The small result in a corner of a 6000 x 6000 grid: the walls' PNGs cover the window
    only, where the view opens, pooled for its size, not the grid's."""
    from pcmapq.report.canvas import window

    grid = MetricGrid(0.1, (1.0, 2.0, 0.0), (6000, 6000))
    walls = np.zeros(grid.shape, bool)
    walls[5950, :80] = True  # beside the features, 0.5 m below y = 2.5 m
    result = replace(small_result(grid), truth_occupied=walls,
                     map_occupied=np.roll(walls, 2, axis=0))
    rows, cols = window(result)
    assert rows.stop - rows.start < VIEWER_PX and cols.stop - cols.start < VIEWER_PX
    page = viewer_html(result, 10.0)
    assert "(here 1 x 1\ncells a pixel)" in page
    x, y, w, h = re.findall(r'<image x="([-\d.]+)" y="([-\d.]+)" width="(\d+)" '
                            r'height="(\d+)"', page)[0]
    assert (float(x), float(y)) == (cols.start - 0.5, rows.start - 0.5)
    assert (int(w), int(h)) == (cols.stop - cols.start, rows.stop - rows.start)
    assert f'viewBox="{cols.start - 0.5:g} {rows.start - 0.5:g} {w} {h}"' in page
