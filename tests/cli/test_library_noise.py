"""Odd but valid inputs: pcmapq's own lines on stderr and nothing from its libraries (NumPy
RuntimeWarnings, OpenCV's or Open3D's logs); an inverted picture refused quickly."""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq import cli
from pcmapq.evaluation.inputs import MAX_OCCUPIED_SHARE
from testkit.command import foreign_lines
from testkit.paths import SAMPLE

TRUTH = SAMPLE / "truth.yaml"


def _image(path: Path, pixels: np.ndarray, negate: int = 0) -> Path:
    """A map_server map: ``path`` (.png) and its YAML (0.05 m cells); returns the YAML."""
    cv2.imwrite(str(path), pixels)
    yaml = path.with_suffix(".yaml")
    yaml.write_text(f"image: {path.name}\nresolution: 0.05\norigin: [0, 0, 0]\n"
                    f"negate: {negate}\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return yaml


def _circle(path: Path) -> Path:
    """A round room: no corners for Harris, no straight walls for Hough."""
    pixels = np.full((200, 200), 254, np.uint8)
    cv2.circle(pixels, (100, 100), 60, 0, 2)
    return _image(path.with_suffix(".png"), pixels)


def _line_image(path: Path) -> Path:
    """One straight wall."""
    pixels = np.full((200, 200), 254, np.uint8)
    pixels[100, 20:180] = 0
    return _image(path.with_suffix(".png"), pixels)


def _far(path: Path) -> Path:
    """The truth's own picture, 1 km away: no overlap at all."""
    png = path.with_suffix(".png")
    png.write_bytes((SAMPLE / "truth.png").read_bytes())
    yaml = path.with_suffix(".yaml")
    yaml.write_text(f"image: {png.name}\nresolution: 0.05\norigin: [1000, 1000, 0]\n")
    return yaml


def _line_points(path: Path) -> Path:
    """500 points on one straight line (a 2D cloud)."""
    np.save(path.with_suffix(".npy"), np.column_stack([np.linspace(0, 10, 500), np.zeros(500)]))
    return path.with_suffix(".npy")


def _sparse_noise(path: Path) -> Path:
    """Scattered occupied pixels, 5 % of the image: structure for no detector."""
    pixels = np.where(np.random.default_rng(1).random((150, 150)) < 0.05, 0, 254)
    return _image(path.with_suffix(".png"), pixels.astype(np.uint8))


#: name: (make the map in a folder, extra options)
CASES: dict[str, tuple[Callable[[Path], Path], tuple[str, ...]]] = {
    "circle_forced": (_circle, ("--force",)),
    "circle_harris_only": (_circle, ("--force", "--detectors", "harris")),
    "one_wall_forced": (_line_image, ("--force",)),
    "far_away_forced": (_far, ("--force",)),
    "far_away_no_align": (_far, ("--no-align",)),
    "points_on_a_line": (_line_points, ()),
    "sparse_noise_forced": (_sparse_noise, ("--force", "--full")),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_odd_inputs_print_only_pcmapq_s_lines(name: str, tmp_path: Path,
                                               capfd: pytest.CaptureFixture[str],
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    make, extra = CASES[name]
    code, foreign = foreign_lines(["eval", str(make(tmp_path / "map")), str(TRUTH), *extra],
                                   capfd, monkeypatch)
    assert code in (0, 1)
    assert foreign == []


@pytest.mark.parametrize("side", ["map", "truth"])
def test_an_inverted_picture_is_refused_quickly(side: str, tmp_path: Path) -> None:
    """The sample's truth read with ``negate: 1`` (95 % occupied; over 90 % once its outside,
    now solid and reaching the border, is read as its face): exit 1, one line naming the file,
    before the alignment (it took over 20 s of CPU to align)."""
    inverted = _image(tmp_path / "inverted.png", cv2.imread(str(SAMPLE / "truth.png"),
                                                            cv2.IMREAD_UNCHANGED), negate=1)
    args = [str(inverted), str(TRUTH)] if side == "map" else [str(TRUTH), str(inverted)]
    start = time.perf_counter()
    got = CliRunner().invoke(cli.app, ["eval", *args, "--force"])
    assert time.perf_counter() - start < 10.0
    assert got.exit_code == 1, got.stderr
    lines = got.stderr.splitlines()
    assert len(lines) == 1 and str(inverted) in lines[0], got.stderr
    share = re.search(r"not a map of walls: (\d+)% of its cells are occupied", lines[0])
    assert share and int(share[1]) > 90, lines[0]


def test_a_map_just_under_the_occupied_share_is_scored(tmp_path: Path) -> None:
    """Stripes one pixel wide, every other row: 50 % occupied, the most that is not refused."""
    pixels = np.full((120, 120), 254, np.uint8)
    pixels[::2] = 0
    assert (pixels == 0).mean() == MAX_OCCUPIED_SHARE
    got = CliRunner().invoke(cli.app, ["eval", str(_image(tmp_path / "s.png", pixels)), str(TRUTH),
                                   "--force"])
    assert got.exit_code == 0, got.stderr
