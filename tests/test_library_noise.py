"""Odd but valid inputs: pcmapq's own lines on stderr and nothing from its libraries (NumPy
RuntimeWarnings, OpenCV's or Open3D's logs); an inverted picture refused quickly."""

from __future__ import annotations

import re
import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

import pcmapq
from pcmapq import cli
from pcmapq.cli import terminal
from pcmapq.evaluation.inputs import MAX_OCCUPIED_SHARE

from .conftest import shared

SAMPLE = Path(__file__).resolve().parents[1] / "data" / "sample"
TRUTH = SAMPLE / "truth.yaml"
PCMAPQ = Path(pcmapq.__file__).parent


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


def _foreign_lines(args: list[str], capfd: pytest.CaptureFixture[str],
                   monkeypatch: pytest.MonkeyPatch) -> tuple[int, list[str]]:
    """Run ``pcmapq ARGS``; its exit code and what of its output is not pcmapq's own: stderr
    lines (Python's, and those C++ libraries write to file descriptor 2) not starting
    "pcmapq: ", and every warning but pcmapq's own UserWarnings (the command line would print
    a NumPy RuntimeWarning as "pcmapq: warning: ...", so warnings are recorded, not shown)."""
    caught: list[warnings.WarningMessage] = []

    @contextmanager
    def recorded(console: object) -> Iterator[None]:
        with warnings.catch_warnings(record=True) as log:
            warnings.simplefilter("always")
            yield
        caught.extend(log)

    monkeypatch.setattr(terminal, "show_warnings", recorded)
    capfd.readouterr()
    got = CliRunner().invoke(cli.app, args)
    outside = capfd.readouterr()
    lines = got.stderr.splitlines() + outside.err.splitlines() + outside.out.splitlines()
    foreign = [line for line in lines if line and not line.startswith("pcmapq: ")]
    foreign += [f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})" for w in caught
                if not (issubclass(w.category, UserWarning) and PCMAPQ in Path(w.filename).parents)
                and (issubclass(w.category, RuntimeWarning) or PCMAPQ in Path(w.filename).parents)]
    return got.exit_code, foreign


@pytest.mark.e2e
@pytest.mark.parametrize("name", sorted(CASES))
def test_odd_inputs_print_only_pcmapq_s_lines(name: str, tmp_path: Path,
                                               capfd: pytest.CaptureFixture[str],
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    make, extra = CASES[name]
    code, foreign = _foreign_lines(["eval", str(make(tmp_path / "map")), str(TRUTH), *extra],
                                   capfd, monkeypatch)
    assert code in (0, 1)
    assert foreign == []


@pytest.mark.realdata
def test_a_carmen_log_prints_only_pcmapq_s_lines(capfd: pytest.CaptureFixture[str],
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    log = shared("carmen", "intel-corrected.log.gz")
    code, foreign = _foreign_lines(["eval", str(log), str(log)], capfd, monkeypatch)
    assert code == 0 and foreign == []


@pytest.mark.e2e
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


@pytest.mark.e2e
def test_a_map_just_under_the_occupied_share_is_scored(tmp_path: Path) -> None:
    """Stripes one pixel wide, every other row: 50 % occupied, the most that is not refused."""
    pixels = np.full((120, 120), 254, np.uint8)
    pixels[::2] = 0
    assert (pixels == 0).mean() == MAX_OCCUPIED_SHARE
    got = CliRunner().invoke(cli.app, ["eval", str(_image(tmp_path / "s.png", pixels)), str(TRUTH),
                                   "--force"])
    assert got.exit_code == 0, got.stderr
