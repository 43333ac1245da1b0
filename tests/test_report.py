"""The pictures and the HTML report."""

from __future__ import annotations

import re
import shutil
import subprocess

import cv2
import numpy as np
import pytest

from pcmapq import synth
from pcmapq.config import MatchingConfig, Settings
from pcmapq.pipeline import evaluate
from pcmapq.report.html import report_html
from pcmapq.report.plot import distance_heatmap, png_bytes, vectorial_figure

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
