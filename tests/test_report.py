"""The pictures and the HTML report."""

from __future__ import annotations

import re
import shutil
import subprocess

import cv2
import numpy as np
import pytest

from pcmapq import synth
from pcmapq.config import Settings
from pcmapq.pipeline import evaluate
from pcmapq.report.html import report_html
from pcmapq.report.plot import distance_heatmap, png_bytes, vectorial_figure

from .conftest import write_image_map


@pytest.fixture(scope="module")
def moved_result(plan, truth_png, tmp_path_factory):
    """A map whose L-shaped wall stands 0.5 m east of the truth's."""
    moved = synth.move_wall(synth.move_wall(plan, 20, (0.5, 0.0)), 21, (0.5, 0.0))
    path = write_image_map(moved, tmp_path_factory.mktemp("moved") / "moved.png")
    return evaluate(path, truth_png, Settings(threshold=1.0))


def decode(png: bytes) -> np.ndarray:
    return cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)


def test_vectorial_figure_draws_the_displacements(moved_result):
    img = decode(png_bytes(vectorial_figure(moved_result)))
    assert img.shape[1] > 2 * img.shape[0]  # three panels side by side
    assert img.std() > 20  # not blank
    # the arrows are black: drawn where the L wall moved, so some pixels are pure black
    assert np.count_nonzero(img.max(axis=2) < 30) > 50


def test_heatmap_colours_the_moved_wall(moved_result):
    img = decode(png_bytes(distance_heatmap(moved_result)))
    # viridis' yellow end (0.5 m, clipped) appears: the moved wall is 0.5 m from the truth
    b, g, r = img[..., 0].astype(int), img[..., 1].astype(int), img[..., 2].astype(int)
    assert np.count_nonzero((r > 200) & (g > 200) & (b < 80)) > 20


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
