"""``pcmapq eval``'s ``"noref"`` block: each input's no-reference figures, as ``pcmapq inspect``
gives them (the map's at eval's voxel and at the estimated scale), the truth's corners without
Harris among the detectors; ``--no-noref`` leaves the block null."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.core.stats import significant
from pcmapq.evaluation.noref_figures import input_figures
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import load_map
from pcmapq.results.result import Result
from pcmapq.settings import (
    AlignmentConfig,
    MatchingConfig,
    NoRefConfig,
    Settings,
    SourceConfig,
)
from testkit.files import write_image_map
from testkit.paths import SAMPLE


def test_eval_reports_the_figures_inspect_gives_for_map_and_truth():
    """The sample: the scan's 3D figures at eval's 0.1 m voxel over eval's sample of 20,000
    points, the truth image's occupancy figures; both equal to input_figures of the loaded
    inputs, and kept by the JSON; the sampled means within three standard errors of the whole
    cloud's."""
    result = evaluate(SAMPLE / "scan.ply", SAMPLE / "truth.yaml")
    scan, truth = load_map(SAMPLE / "scan.ply"), load_map(SAMPLE / "truth.yaml")
    assert result.noref["map"] == input_figures(scan, Settings().noref)
    assert result.noref["truth"] == input_figures(truth, Settings().noref)
    cloud = result.noref["map"]["cloud"]
    assert cloud["voxel_m"] == 0.1 and cloud["points"] < len(scan.points)
    assert cloud["sampled_points"] == 20_000 == cloud["mpv_points"] + 6  # 6 with few neighbours
    assert result.noref["map"]["grid"] is None and result.noref["truth"]["cloud"] is None
    assert result.noref["truth"]["grid"]["occupied_cells"] > 0
    # in the JSON, to six significant digits (MPV and MOM are small areas)
    assert Result.from_json(result.to_json()).noref == significant(result.noref)
    assert significant(cloud)["mme"] != cloud["mme"]  # the rounding is not a no-op here
    got = CliRunner().invoke(app, ["inspect", str(SAMPLE / "scan.ply"), "--noref-voxel",
                                   "0.1", "--noref-sample", "20000", "--json", "-"])
    assert got.exit_code == 0, got.stderr
    # what the docs say: inspect --noref-voxel 0.1 --noref-sample 20000
    assert json.loads(got.stdout)["cloud"] == significant(cloud)
    whole = CliRunner().invoke(app, ["inspect", str(SAMPLE / "scan.ply"),
                                     "--noref-voxel", "0.1", "--json", "-"])
    whole = json.loads(whole.stdout)["cloud"]
    assert whole["sampled_points"] is None and whole["mpv_points"] > 100_000
    for name in ("mme", "mpv"):
        assert abs(whole[name] - cloud[name]) < 3 * cloud[f"{name}_se"]
    floats = [v for v in json.loads(got.stdout)["cloud"].values() if isinstance(v, float)]
    assert floats and all(v in (round(v, 6), float(f"{v:.6g}")) for v in floats)


def test_no_noref_leaves_the_block_null(plan, truth_png, tmp_path):
    settings = replace(Settings(), noref=NoRefConfig(enabled=False))
    result = evaluate(truth_png, truth_png, settings)
    assert result.noref is None and result.to_dict()["noref"] is None
    assert result.to_dict()["settings"]["noref"]["enabled"] is False


def test_the_truths_corners_without_harris_among_the_detectors(truth_png):
    """Eval takes an image truth's corners from its own Harris detection; run without Harris,
    it counts them itself: the same figures."""
    with_harris = evaluate(truth_png, truth_png).noref["truth"]
    settings = replace(Settings(), matching=MatchingConfig(detectors=("sift",)))
    assert evaluate(truth_png, truth_png, settings).noref["truth"] == with_harris
    assert with_harris == input_figures(load_map(truth_png), Settings().noref)


def test_a_map_of_unknown_scale_gets_figures_in_the_truths_metres(plan, truth_png, tmp_path):
    """The plan drawn at 0.05 m a pixel but read as 0.1 m, scale estimated: its figures are
    those of 0.05 m cells (corner and enclosed-area parameters are in metres)."""
    path = write_image_map(plan, tmp_path / "map.png")
    settings = Settings(map=SourceConfig(resolution=0.1), alignment=AlignmentConfig(scale=True))
    result = evaluate(path, truth_png, settings)
    got = result.noref["map"]["grid"]
    assert result.transform.scale == pytest.approx(0.5, abs=0.01)
    assert got["resolution_m"] == pytest.approx(0.05, abs=0.001)
    want = input_figures(load_map(path), Settings().noref)["grid"]
    assert got["corners"] == want["corners"]
    assert got["enclosed_areas"] == want["enclosed_areas"]
