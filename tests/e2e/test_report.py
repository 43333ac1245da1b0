"""The pictures and the HTML report."""

from __future__ import annotations

import re
import shutil
from dataclasses import replace

import cv2
import matplotlib
import numpy as np
import pytest

from pcmapq.core.bounds import nonzero_window
from pcmapq.core.grid import MetricGrid
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.arrows import auto_arrow_scale
from pcmapq.report.canvas import MARGIN_MIN_M, extent, overlay, window
from pcmapq.report.heatmap import distance_heatmap
from pcmapq.report.html import report_html
from pcmapq.report.plot import png_bytes, vectorial_figure
from pcmapq.report.style import DPI, FIGURE_WIDTH_PX, MAP_LIGHT
from pcmapq.report.text import number
from pcmapq.report.viewer import viewer_html
from pcmapq.settings import MatchingConfig, Settings
from testkit import synth
from testkit.files import write_image_map
from testkit.viewer import chromium

#: The colour of the truth's walls where no map wall is under them.
TRUTH_ON_WHITE = tuple(overlay(np.ones((1, 1)), np.zeros((1, 1)))[0, 0])


@pytest.fixture(scope="module")
def moved_result(plan, truth_png, tmp_path_factory):
    """A map whose L-shaped wall stands 0.5 m east of the truth's."""
    moved = synth.move_wall(synth.move_wall(plan, 20, (0.5, 0.0)), 21, (0.5, 0.0))
    path = write_image_map(moved, tmp_path_factory.mktemp("moved") / "moved.png")
    return evaluate(path, truth_png, Settings(matching=MatchingConfig(threshold=1.0)))


@pytest.fixture(scope="module")
def perfect_result(truth_png):
    """The truth scored against itself: nothing moved."""
    return evaluate(truth_png, truth_png)


#: The command line the report of :func:`moved_page` names.
COMMAND = "pcmapq eval moved.png truth.png --threshold 0.5"


@pytest.fixture(scope="module")
def moved_page(moved_result) -> str:
    """The report of the moved result, its command line COMMAND, made once for the tests that
    read it."""
    return report_html(replace(moved_result, command=COMMAND))


#: Where the moved L wall's vertical arm stands in the map (truth frame, metres): x0, x1, y0, y1.
MOVED_ARM = (19.6, 20.2, 2.0, 3.5)


def region(fig, ax, box: tuple[float, float, float, float], dpi: int = 130):
    """The pixels of ``png_bytes(fig, dpi)`` that show the data box (x0, x1, y0, y1) of ``ax``:
    (rows, cols, 3) BGR."""
    img = cv2.imdecode(np.frombuffer(png_bytes(fig, dpi), np.uint8), cv2.IMREAD_COLOR)
    x0, x1, y0, y1 = box
    corners = ax.transData.transform([[x0, y0], [x1, y1]]) * (dpi / fig.dpi)
    (u0, v0), (u1, v1) = np.round(corners).astype(int)
    rows = img.shape[0]
    return img[rows - max(v0, v1): rows - min(v0, v1), min(u0, u1): max(u0, u1)]


def test_vectorial_figure_draws_the_displacements(moved_result, perfect_result):
    """Black arrows where the wall moved, the figure's scale times its 0.5 m long, none there
    when nothing moved (Hough panel: the arm's displacement is drawn at its midpoint; the
    truth's dark walls are lighter than the arrows)."""
    arrows = (MOVED_ARM[0], MOVED_ARM[0] + 0.5 * auto_arrow_scale(moved_result), *MOVED_ARM[2:])

    def black(result) -> int:
        fig = vectorial_figure(result)
        ax = fig.axes[list(result.detectors).index("hough")]
        return int(np.count_nonzero(region(fig, ax, arrows).max(axis=2) < 25))

    assert black(moved_result) > 20
    assert black(perfect_result) == 0


def heatmap_yellow(result, panel: int, box: tuple) -> int:
    """Pixels of viridis' yellow end (distances clipped at 0.5 m) in ``box`` of the distance
    heatmap's panel ``panel``."""
    fig = distance_heatmap(result)
    img = region(fig, fig.axes[panel], box).astype(int)
    b, g, r = img[..., 0], img[..., 1], img[..., 2]
    return int(np.count_nonzero((r > 200) & (g > 200) & (b < 80)))


def test_heatmap_colours_the_moved_wall(moved_result, perfect_result):
    """viridis' yellow end (0.5 m, clipped) on the moved arm, none there when nothing moved."""
    assert heatmap_yellow(moved_result, 0, MOVED_ARM) > 10
    assert heatmap_yellow(perfect_result, 0, MOVED_ARM) == 0


def test_report_is_self_contained(moved_result, moved_page):
    page = moved_page
    assert not re.search(r'(src|href)="(https?:)?//', page)  # nothing fetched from a network
    assert page.count("data:image/png;base64,") == 4  # two figures, the viewer's two walls
    assert f"displacement x{auto_arrow_scale(moved_result):g}" not in page  # in the figure
    q = moved_result.detectors["harris"].matching.quality
    assert f"{q:.3f}" in page and "coverage" in page


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Debian's chromium is not installed")
def test_report_renders_in_chromium(moved_page, tmp_path):
    page = tmp_path / "report.html"
    page.write_text(moved_page)
    shot = tmp_path / "shot.png"
    chromium(page, tmp_path, 1400, 2400, f"--screenshot={shot}")
    img = cv2.imread(str(shot))
    assert img is not None and img.shape[:2] == (2400, 1400)
    # the embedded figures rendered: many non-white, coloured pixels
    assert np.count_nonzero(img.min(axis=2) < 200) > 20000


#: A grid ten times finer (0.005 m, 3610 x 5210 cells) over the moved result's extent, more
#: cells than a panel has pixels: truth walls one cell thin at these x (vertical) and y
#: (horizontal), metres; the map's one-cell walls MAP_SHIFT east of the vertical ones.
FINE = 0.005
TRUTH_X, TRUTH_Y, MAP_SHIFT = (3.0025, 9.0025, 15.0025), 12.0475, 0.3


@pytest.fixture(scope="module")
def fine_result(moved_result):
    """The moved result with its rasters replaced by the one-cell walls above (footprint: all)."""
    coarse = moved_result.grid
    n = round(coarse.resolution / FINE)
    grid = MetricGrid(FINE, coarse.origin, (coarse.shape[0] * n, coarse.shape[1] * n))
    u_truth, v_truth = np.round(grid.xy_to_pixels([(x, TRUTH_Y) for x in TRUTH_X])).astype(int).T
    u_map = np.round(grid.xy_to_pixels([(x + MAP_SHIFT, 0.0) for x in TRUTH_X])[:, 0]).astype(int)
    truth, walls = np.zeros(grid.shape, bool), np.zeros(grid.shape, bool)
    truth[:, u_truth] = True
    truth[v_truth[0], :] = True
    walls[:, u_map] = True
    return replace(moved_result, grid=grid, truth_occupied=truth, map_occupied=walls,
                   overlap=replace(moved_result.overlap, footprint=np.ones(grid.shape, bool)))


def runs(line: np.ndarray, box: tuple[float, float, float, float], axis: int) -> list[float]:
    """Centres, metres, of the runs of true pixels along a row (``axis`` 0: x) or column (1: y)
    of the pixels that show the data ``box`` (x0, x1, y0, y1)."""
    idx = np.flatnonzero(line)
    groups = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if len(idx) else []
    lo, hi = (box[0], box[1]) if axis == 0 else (box[3], box[2])  # image rows run down
    return [lo + (g.mean() + 0.5) / len(line) * (hi - lo) for g in groups]


def coloured(img: np.ndarray, rgb: tuple[float, float, float]) -> np.ndarray:
    """Pixels of the BGR ``img`` within 3 levels of the colour ``rgb`` (0-1 floats)."""
    bgr = np.array(rgb[::-1]) * 255
    return np.abs(img.astype(float) - bgr).max(axis=2) <= 3


def test_large_grids_are_pooled_and_one_cell_walls_drawn_in_place(fine_result, moved_result):
    """Every one-cell wall of a grid larger than the panel shows, where it stands in metres
    (within one pooled cell and one pixel), and the pooled raster has no more cells than the
    axes pixels; a grid that fits is drawn cell for cell."""
    fig = vectorial_figure(fine_result)
    ax = fig.axes[0]
    box = extent(fine_result)
    img = region(fig, ax, box)
    shown = ax.images[0].get_array().shape[:2]
    factor = -(-fine_result.grid.shape[1] // shown[1])
    bb = ax.get_window_extent()
    assert factor > 1 and shown == tuple(-(-np.array(fine_result.grid.shape) // factor))
    assert shown[0] <= bb.height * DPI / fig.dpi and shown[1] <= bb.width * DPI / fig.dpi
    tol = factor * FINE + (box[1] - box[0]) / img.shape[1]
    grey, blue = coloured(img, TRUTH_ON_WHITE), coloured(img, MAP_LIGHT)
    np.testing.assert_allclose(runs(grey.mean(axis=0) > 0.5, box, 0), TRUTH_X, atol=tol)
    np.testing.assert_allclose(runs(grey.mean(axis=1) > 0.5, box, 1), [TRUTH_Y], atol=tol)
    np.testing.assert_allclose(runs(blue.mean(axis=0) > 0.5, box, 0),
                               np.add(TRUTH_X, MAP_SHIFT), atol=tol)
    small = vectorial_figure(moved_result)
    assert small.axes[0].images[0].get_array().shape[:2] == moved_result.grid.shape


def test_heatmap_of_a_large_grid_colours_each_wall_by_its_distance(fine_result):
    """The map's walls, 0.3 m from the truth's, in viridis' colour of 0.3 m (of 0.5), where
    they stand."""
    fig = distance_heatmap(fine_result)
    box = extent(fine_result)
    img = region(fig, fig.axes[0], box)
    at_shift = coloured(img, matplotlib.colormaps["viridis"](MAP_SHIFT / 0.5)[:3])
    tol = 2 * (box[1] - box[0]) / img.shape[1]
    np.testing.assert_allclose(runs(at_shift.mean(axis=0) > 0.5, box, 0),
                               np.add(TRUTH_X, MAP_SHIFT), atol=tol)


def test_truth_shows_where_the_map_lies_on_it(perfect_result):
    """The truth scored against itself: every map wall lies on a truth wall, yet the truth's
    dark walls show (over the map's light ones, which show at their edges)."""
    fig = vectorial_figure(perfect_result)
    img = region(fig, fig.axes[0], extent(perfect_result, 1, window(perfect_result)))
    walls = int(np.count_nonzero(perfect_result.truth_occupied))
    dark = np.count_nonzero(img.max(axis=2) < 80)
    assert dark > 0.5 * walls
    assert np.count_nonzero(coloured(img, MAP_LIGHT)) > 0.5 * walls


#: Empty grid added on every side of a result's: a building in the middle of a large plan image.
PAD_M = 40.0


def test_a_plan_in_a_large_image_fills_its_panels(moved_result):
    """The moved result with PAD_M metres of empty grid on every side: every panel of the
    figure and of the heatmap, and the viewer's first view, show the walls' box with its
    margin, not the grid; drawn cell for cell, as the grid alone is."""
    base = moved_result.grid
    pad = round(PAD_M / base.resolution)
    grid = MetricGrid(base.resolution, (base.origin[0] - pad * base.resolution,
                                        base.origin[1] - pad * base.resolution, 0.0),
                      (base.shape[0] + 2 * pad, base.shape[1] + 2 * pad))
    padded = replace(
        moved_result, grid=grid, truth_occupied=np.pad(moved_result.truth_occupied, pad),
        map_occupied=np.pad(moved_result.map_occupied, pad),
        overlap=replace(moved_result.overlap,
                        footprint=np.pad(moved_result.overlap.footprint, pad)),
        detectors={k: v for k, v in moved_result.detectors.items() if k != "rooms"}, rooms=None)
    lo, hi, left, right = nonzero_window(padded.truth_occupied | padded.map_occupied)
    walls = (grid.origin[0] + left * grid.resolution, grid.origin[0] + right * grid.resolution,
             grid.origin[1] + (grid.shape[0] - hi) * grid.resolution,
             grid.origin[1] + (grid.shape[0] - lo) * grid.resolution)
    shown = window(padded)
    box = extent(padded, 1, shown)
    assert box[1] - box[0] < grid.size_m[0] - 2 * PAD_M + 2 * MARGIN_MIN_M + 10.0
    assert box[0] <= walls[0] - MARGIN_MIN_M and box[1] >= walls[1] + MARGIN_MIN_M
    assert box[2] <= walls[2] - MARGIN_MIN_M and box[3] >= walls[3] + MARGIN_MIN_M
    for fig in (vectorial_figure(padded), distance_heatmap(padded)):
        panels = [ax for ax in fig.axes if ax.images]
        assert len(panels) >= 2
        for ax in panels:
            np.testing.assert_allclose([*ax.get_xlim(), *ax.get_ylim()], box)
            assert ax.images[0].get_array().shape[:2] == padded.truth_occupied[shown].shape
    view = re.search(r'viewBox="([^"]+)"', viewer_html(padded, 10.0)).group(1)
    np.testing.assert_allclose([float(v) for v in view.split()],
                               [shown[1].start - 0.5, shown[0].start - 0.5,
                                shown[1].stop - shown[1].start, shown[0].stop - shown[0].start])


def _inside(inner, outer) -> bool:
    return (inner.x0 >= outer.x0 - 0.5 and inner.y0 >= outer.y0 - 0.5
            and inner.x1 <= outer.x1 + 0.5 and inner.y1 <= outer.y1 + 0.5)


@pytest.mark.parametrize("names", [("harris",), ("harris", "hough"), ("harris", "hough", "sift")])
def test_legend_and_scale_bars_inside_the_canvas_and_off_the_data(moved_result, names):
    """With one, two or three detectors: the legend and every scale bar lie whole inside the
    figure and overlap no panel's data area; no two texts overlap."""
    result = replace(moved_result, detectors={n: moved_result.detectors[n] for n in names})
    fig = vectorial_figure(result)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    panels = [ax for ax in fig.axes if ax.images]
    assert len(result.consistency.points)  # the regions' panel follows the detectors'
    assert len(panels) == len(names) + 1
    legends = fig.legends + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    bars = [a for ax in panels for a in ax.artists]
    assert len(legends) == 1 and len(bars) == len(names) + 1
    for artist in legends + bars:
        box = artist.get_window_extent(renderer)
        assert _inside(box, fig.bbox), (artist, box, fig.bbox)
        assert not any(box.overlaps(ax.get_window_extent(renderer)) for ax in panels)
    texts = [t for ax in panels for t in (ax.title, ax.xaxis.label)]
    boxes = [t.get_window_extent(renderer) for t in texts] + \
            [a.get_window_extent(renderer) for a in bars + legends]
    for i, a in enumerate(boxes):
        assert _inside(a, fig.bbox)
        assert not any(a.overlaps(b) for b in boxes[i + 1:]), a


def test_arrow_scale_is_one_for_every_panel_and_run(moved_result, fine_result):
    """Two maps of different grids: every panel's arrows are one scale times their
    displacement in metres, and the legend says so; --arrow-scale changes every one."""
    for result in (moved_result, fine_result):
        for gain, chosen in ((auto_arrow_scale(result), None), (3.0, 3.0)):
            fig = vectorial_figure(result, chosen)
            quivers = [c for ax in fig.axes for c in ax.collections if hasattr(c, "scale_units")]
            assert quivers and {(q.scale_units, q.scale) for q in quivers} == {("xy", 1 / gain)}
            legend = (fig.legends or [ax.get_legend() for ax in fig.axes if ax.get_legend()])[0]
            assert f"displacement x{gain:g} (0.1 m drawn {0.1 * gain:g} m), truth to map" in \
                [t.get_text() for t in legend.get_texts()]


def test_fonts_read_at_the_reports_width(moved_result, moved_page):
    """The figures are no wider than the report shows them, so none is scaled down there, and
    every text in them is at least 12 pixels high."""
    assert f"max-width: {FIGURE_WIDTH_PX + 50}px" in moved_page
    for fig in (vectorial_figure(moved_result), distance_heatmap(moved_result)):
        assert fig.get_figwidth() * DPI <= FIGURE_WIDTH_PX
        sizes = [t.get_fontsize() for t in fig.findobj(matplotlib.text.Text)
                 if t.get_visible() and t.get_text()]
        assert sizes and min(sizes) * DPI / 72 >= 12, min(sizes)


def test_completeness_heatmap_colours_the_truth_wall_the_map_left(moved_result,
                                                                  perfect_result):
    """Right panel: the truth's arm, 0.5 m west of where the map has it, in viridis' yellow
    (0.5 m); none there when nothing moved."""
    truth_arm = (MOVED_ARM[0] - 0.5, MOVED_ARM[1] - 0.5, *MOVED_ARM[2:])
    assert heatmap_yellow(moved_result, 1, truth_arm) > 10
    assert heatmap_yellow(perfect_result, 1, truth_arm) == 0


def test_report_lists_every_missing_and_extra_feature(moved_result):
    """Matched within 0.2 m, the features of the wall moved by 0.5 m are missing and extra:
    the report lists each, with its position."""
    strict = evaluate(moved_result.map_path, moved_result.truth_path,
                      Settings(matching=MatchingConfig(threshold=0.2)))
    page = report_html(strict)
    for name, det in strict.detectors.items():
        m = det.matching
        assert f"{name}: {len(m.missing)} missing" in page
        assert f"{name}: {len(m.extra)} extra" in page
        for x, y in np.vstack([det.truth.xy[m.missing], det.map.xy[m.extra]]):
            assert f"<td>{number(x)}</td><td>{number(y)}</td>" in page
    assert sum(len(d.matching.missing) for d in strict.detectors.values()) > 0
    assert sum(len(d.matching.extra) for d in strict.detectors.values()) > 0


def test_lidar_pair_is_drawn_as_density_with_fewer_markers(moved_result):
    """Marked as two 3D clouds, the same result is drawn as a density (shades between the
    map's and the truth's full colours) with markers thinned to wider squares."""
    from pcmapq.align.rigid3d import Registration3D

    lidar = replace(moved_result, registration_3d=Registration3D(np.eye(4), 1.0, 0.0))
    fine = replace(lidar, grid=MetricGrid(0.01, lidar.grid.origin, lidar.grid.shape))

    def markers(result) -> int:
        fig = vectorial_figure(result)
        return sum(len(c.get_offsets()) for ax in fig.axes for c in ax.collections
                   if type(c).__name__ == "PathCollection")

    assert markers(fine) < markers(replace(fine, registration_3d=None))
    fig = vectorial_figure(lidar)
    assert "occupied share" in " ".join(t.get_text() for t in fig.findobj(matplotlib.text.Text))


def test_report_says_how_it_was_made(moved_result, moved_page):
    """The report holds pcmapq's version, the command line and every setting, as the JSON
    does."""
    import html as html_module
    import json as json_module

    from pcmapq import __version__

    result, page = replace(moved_result, command=COMMAND), moved_page
    assert f"pcmapq {__version__}; command: <code>pcmapq eval moved.png truth.png" in page
    settings = json_module.loads(html_module.unescape(
        page.split("<summary>settings</summary><pre>")[1].split("</pre>")[0]))
    assert settings == json_module.loads(result.to_json())["settings"]
