"""Inputs whose extent looks wrong (a copy or an outlier far away, millimetres, a resolution
not in metres, one straight wall) are refused on the command line with one line that says what
looks wrong and how to fix it; ``--map-crop`` / ``--truth-crop`` keep the part that matters and
then score as the clean input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from testkit.paths import SAMPLE


def _eval(*args: str) -> tuple[int, str, str]:
    got = CliRunner().invoke(app, ["eval", *args])
    return got.exit_code, got.stdout, got.stderr


def _crop_option(stderr: str, option: str) -> str:
    return stderr.split(f"{option} ")[-1].split(" keeps")[0]


def test_a_truth_with_a_copy_far_away_is_refused_then_cropped_to_the_clean_result(
        tmp_path, scan_points):
    """The sample's scan as truth, plus its copy 20 km away: refused (exit 2) with the box of the
    near copy; with that --truth-crop it scores exactly as the clean truth."""
    clean, doubled = tmp_path / "clean.npy", tmp_path / "doubled.npy"
    np.save(clean, scan_points)
    np.save(doubled, np.vstack([scan_points, scan_points + [20_000.0, 0.0, 0.0]]))
    code, _, stderr = _eval(str(SAMPLE / "truth.png"), str(doubled), "--max-memory", "4")
    assert code == 2 and len(stderr.strip().splitlines()) == 1, stderr
    assert f"{len(scan_points):,} of its {2 * len(scan_points):,} points lie far" in stderr
    box = _crop_option(stderr, "--truth-crop")
    runs = []
    for truth, extra in ((clean, []), (doubled, ["--truth-crop", box])):
        out = tmp_path / f"{truth.stem}.json"
        code, _, stderr = _eval(str(SAMPLE / "truth.png"), str(truth), "--quiet", "--json",
                                str(out), *extra)
        assert code == 0, stderr
        runs.append(json.loads(out.read_text()))
    clean_run, cropped_run = runs
    for name in ("harris", "hough", "sift"):
        assert cropped_run["detectors"][name] == clean_run["detectors"][name]
    assert cropped_run["settings"]["truth"]["crop"] == [float(v) for v in box.split(",")]


def test_a_map_with_a_point_at_1e300_is_refused_then_cropped(tmp_path, scan_points):
    path = tmp_path / "outlier.npy"
    np.save(path, np.vstack([scan_points, [[1e300, 0.0, 1.0]]]))
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"))
    assert code == 2 and "wider than 100 km" in stderr and "1 of its" in stderr, stderr
    assert "Traceback" not in stderr and len(stderr.strip().splitlines()) == 1
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"), "--quiet", "--map-crop",
                            _crop_option(stderr, "--map-crop"))
    assert code == 0, stderr


@pytest.mark.unit  # stops before the search
def test_a_map_in_millimetres_with_scale_auto_says_so(tmp_path, scan_points):
    path = tmp_path / "mm.npy"
    np.save(path, scan_points[::10] * 1000.0)  # a tenth of the scan spans what it spans
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"), "--scale", "auto")
    assert code == 1 and "lowest scale --scale auto tries (0.2)" in stderr, stderr
    assert "millimetres" in stderr and len(stderr.strip().splitlines()) == 1


@pytest.mark.unit  # stops before the search
@pytest.mark.parametrize("mistake", ["millimetres", "cells of 50 m"])
def test_a_unit_mistake_on_the_map_side_is_refused_before_the_search(mistake, tmp_path,
                                                                      scan_points, monkeypatch):
    """The truth's mistakes, made on the map's side (a cloud in millimetres, a YAML whose
    resolution is 50): exit 1 with the same reason the truth's side gives, before the global
    search, which took 30-40 s and 8 GB on them."""
    if mistake == "millimetres":
        path = tmp_path / "mm.npy"
        np.save(path, scan_points[::10] * 1000.0)  # a tenth of the scan spans what it spans
        why = "millimetres"
    else:
        (tmp_path / "t.png").write_bytes((SAMPLE / "truth.png").read_bytes())
        text = (SAMPLE / "truth.yaml").read_text()
        path = tmp_path / "t.yaml"
        path.write_text("\n".join("resolution: 50" if line.startswith("resolution") else
                                  "image: t.png" if line.startswith("image") else line
                                  for line in text.splitlines()))
        why = "its cells are 50 m wide"
    called = []
    import pcmapq.align.planar as planar

    original = planar.coarse_search
    monkeypatch.setattr(planar, "coarse_search",
                        lambda *a, **k: called.append(1) or original(*a, **k))
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"))
    assert code == 1 and why in stderr and str(path) in stderr, stderr
    assert len(stderr.strip().splitlines()) == 1 and not called


@pytest.mark.unit  # stops before the search
def test_a_map_of_one_straight_wall_is_refused_with_exit_1(tmp_path):
    path = tmp_path / "line.npy"
    np.save(path, np.column_stack([np.linspace(0, 10, 2000), np.zeros(2000)]))
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"))
    assert code == 1 and "one straight line" in stderr and str(path) in stderr, stderr


@pytest.mark.unit  # stops before the search
def test_max_memory_reaches_the_loaders(tmp_path):
    """A limit below what the truth image needs stops at its header (the loader), naming it."""
    code, _, stderr = _eval(str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.yaml"),
                            "--max-memory", "0.1")
    assert code == 2 and "truth.png (521 x 361 pixels declared in its header)" in stderr, stderr


def test_inspect_refuses_a_yaml_of_50_m_cells_in_one_line(tmp_path):
    """`pcmapq inspect` goes through eval's input checks: the sample's YAML with resolution 50
    (a 26 km image whose walls' image would take terabytes) is refused from its size, with
    the reason, in one line; it ended in an OpenCV traceback."""
    (tmp_path / "t.png").write_bytes((SAMPLE / "truth.png").read_bytes())
    path = tmp_path / "t.yaml"
    path.write_text("\n".join("resolution: 50" if line.startswith("resolution") else
                              "image: t.png" if line.startswith("image") else line
                              for line in (SAMPLE / "truth.yaml").read_text().splitlines()))
    got = CliRunner().invoke(app, ["inspect", str(path)])
    assert got.exit_code == 2 and "its cells are 50 m wide" in got.stderr, got.stderr
    assert len(got.stderr.strip().splitlines()) == 1 and str(path) in got.stderr
