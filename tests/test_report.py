"""The pictures and the HTML report."""

from __future__ import annotations

import re
import shutil
import subprocess
from dataclasses import replace

import cv2
import matplotlib
import numpy as np
import pytest

from pcmapq import synth
from pcmapq.config import MatchingConfig, Settings
from pcmapq.grid import MetricGrid
from pcmapq.pipeline import evaluate
from pcmapq.report.html import report_html
from pcmapq.report.plot import (
    DPI,
    MAP_BLUE,
    TRUTH_GREY,
    distance_heatmap,
    extent,
    png_bytes,
    vectorial_figure,
    wall_distances,
)

from .conftest import write_image_map


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
    """Black arrows where the wall moved, none there when nothing moved (Hough panel: the
    arm's displacement is drawn at its midpoint)."""
    def black(result) -> int:
        fig = vectorial_figure(result)
        ax = fig.axes[list(result.detectors).index("hough")]
        return int(np.count_nonzero(region(fig, ax, MOVED_ARM).max(axis=2) < 60))

    assert black(moved_result) > 20
    assert black(perfect_result) == 0


def test_heatmap_colours_the_moved_wall(moved_result, perfect_result):
    """viridis' yellow end (0.5 m, clipped) on the moved arm, none there when nothing moved."""
    def yellow(result) -> int:
        fig = distance_heatmap(result)
        img = region(fig, fig.axes[0], MOVED_ARM).astype(int)
        b, g, r = img[..., 0], img[..., 1], img[..., 2]
        return int(np.count_nonzero((r > 200) & (g > 200) & (b < 80)))

    assert yellow(moved_result) > 10
    assert yellow(perfect_result) == 0


def test_report_is_self_contained(moved_result):
    page = report_html(moved_result)
    assert not re.search(r'(src|href)="(https?:)?//', page)  # nothing fetched from a network
    assert page.count("data:image/png;base64,") == 2
    q = moved_result.detectors["harris"].matching.quality
    assert f"{q:.3f}" in page and "coverage" in page


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Debian's chromium is not installed")
def test_report_renders_in_chromium(moved_result, tmp_path):
    page = tmp_path / "report.html"
    page.write_text(report_html(moved_result))
    shot = tmp_path / "shot.png"
    subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                    "--no-first-run", "--disable-background-networking",
                    "--disable-component-update", "--disable-sync",
                    f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1400,2400",
                    f"--screenshot={shot}", page.as_uri()],
                   capture_output=True, timeout=120, check=True)
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
    grey, blue = coloured(img, TRUTH_GREY), coloured(img, MAP_BLUE)
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


def test_wall_distances_keep_the_nearest_cell_of_each_block():
    """Truth wall in column 0 of 0.01 m cells; map cells 3 and 7 cells from it in one 10 x 10
    block, 12 cells in another: 0.03 m and 0.12 m, NaN where a block has no map cell."""
    truth, walls = np.zeros((20, 20), bool), np.zeros((20, 20), bool)
    truth[:, 0] = True
    walls[2, 3] = walls[5, 7] = walls[15, 12] = True
    np.testing.assert_allclose(wall_distances(truth, walls, 0.01, 10),
                               [[0.03, np.nan], [np.nan, 0.12]], rtol=1e-6)
