"""``pcmapq inspect``: no-reference figures from the command line, equal to the library's on the
same points, and one-line usage errors (map-metrics' own figures on its data:
tests/realdata/test_map_metrics.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.io import load_map
from pcmapq.metrics import noref
from pcmapq.raster.draw import FREE, OCCUPIED
from testkit.paths import SAMPLE


def _inspect(*args: str) -> tuple[int, str, str]:
    got = CliRunner().invoke(app, ["inspect", *args])
    return got.exit_code, got.stdout, got.stderr


def test_a_3d_cloud_gets_the_library_figures_and_the_same_json_twice(tmp_path):
    """A noisy floor and two walls (1 cm noise): the JSON holds noref.scores' MME and MPV of
    the same points (rounded: see pcmapq.core.stats.significant) and is byte-identical across
    runs; the floor alone has an MPV of the noise's variance."""
    rng = np.random.default_rng(5)
    floor = np.column_stack([rng.uniform(0, 4, (3000, 2)), rng.normal(0, 0.01, 3000)])
    wall_x = np.column_stack([rng.normal(0, 0.01, 3000), rng.uniform(0, 4, 3000),
                              rng.uniform(0, 2, 3000)])
    wall_y = np.column_stack([rng.uniform(0, 4, 3000), rng.normal(0, 0.01, 3000),
                              rng.uniform(0, 2, 3000)])
    points = np.vstack([floor, wall_x, wall_y])
    path = tmp_path / "room.npy"
    np.save(path, points)
    texts = []
    for _ in range(2):  # one path: the JSON holds the command line
        code, _, stderr = _inspect(str(path), "--noref-radius", "0.3", "--json",
                                   str(tmp_path / "r.json"), "--quiet")
        assert code == 0, stderr
        texts.append((tmp_path / "r.json").read_text())
    assert texts[0] == texts[1]
    got = json.loads(texts[0])["cloud"]
    want = noref.scores(points, 0.3, noref.MIN_KNN)
    # the JSON's figures: 6 decimals, or 6 significant digits where that keeps more
    assert got["mme"] == round(want.mme, 6) and got["mpv"] == float(f"{want.mpv:.6g}")
    assert got["points"] == len(points) and got["radius_m"] == 0.3
    np.save(path, floor)  # one plane alone: MPV is the noise's variance, 1e-4 m^2
    code, stdout, stderr = _inspect(str(path), "--noref-radius", "0.3", "--json", "-")
    assert code == 0, stderr
    assert json.loads(stdout)["cloud"]["mpv"] == pytest.approx(1e-4, rel=0.1)


@pytest.mark.unit
def test_an_image_gets_its_occupancy_figures():
    code, stdout, stderr = _inspect(str(SAMPLE / "truth.yaml"), "--json", "-")
    assert code == 0, stderr
    grid = json.loads(stdout)["grid"]
    state = load_map(SAMPLE / "truth.yaml").state
    assert grid["occupied_cells"] == int((state == OCCUPIED).sum())
    assert grid["free_cells"] == int((state == FREE).sum())
    assert grid["resolution_m"] == 0.05 and grid["corners"] > 0
    assert json.loads(stdout)["cloud"] is None


@pytest.mark.unit
@pytest.mark.parametrize("args", [[], ["--scans", "x"], ["m.ply", "--scans", "x", "--poses", "p"],
                                  ["m.ply", "--orth-pose", "p.txt"]])
def test_usage_mistakes_are_one_line_exit_2(args):
    code, _, stderr = _inspect(*args)
    assert code == 2 and len(stderr.strip().splitlines()) == 1, stderr
    assert stderr.startswith("pcmapq: error:"), stderr


@pytest.mark.unit
def test_a_2d_cloud_gets_its_occupied_cells_and_no_free_space(tmp_path):
    """An L of 100 points 0.1 m apart, each given twice: 100 occupied 0.05 m cells; a cloud has
    no free cells, so its ratio and enclosed areas are None."""
    leg = np.arange(50) * 0.1 + 0.025
    xy = np.vstack([np.column_stack([leg, np.full(50, 0.025)]),
                    np.column_stack([np.full(50, -0.475), leg + 0.5])])
    path = tmp_path / "l.npy"
    np.save(path, np.vstack([xy, xy]))
    code, stdout, stderr = _inspect(str(path), "--json", "-")
    assert code == 0, stderr
    grid = json.loads(stdout)["grid"]
    assert grid["occupied_cells"] == 100 and grid["resolution_m"] == 0.05
    assert grid["free_cells"] is None and grid["enclosed_areas"] is None
