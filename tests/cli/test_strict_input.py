"""Strict numbers: non-finite option values refused at parsing (exit 2, before any work), and
the JSON strict (no bare NaN / Infinity)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.results.result import Result
from testkit.paths import SAMPLE

TRUTH = str(SAMPLE / "truth.png")


@pytest.mark.unit
@pytest.mark.parametrize("option", [
    ["--tau", "nan"], ["--tau", "0.1,inf"], ["--tau", "-inf"], ["--threshold", "inf"],
    ["--threshold", "nan"], ["--init", "nan,0,0"], ["--init", "0,inf,0"],
    ["--map-resolution", "inf"], ["--map-resolution", "nan"], ["--truth-resolution", "inf"],
    ["--truth-resolution", "nan"], ["--band-low", "nan"], ["--band-high", "inf"],
    ["--arrow-scale", "inf"], ["--voxel-3d", "nan"], ["--max-memory", "inf"],
    ["--map-occupied-thresh", "nan"], ["--truth-free-thresh", "nan"]])
def test_non_finite_option_values_are_refused_at_parsing(option: list[str], tmp_path: Path):
    """Exit 2, the option named on the error line, no traceback, nothing written."""
    out = tmp_path / "r.json"
    got = CliRunner().invoke(app, ["eval", TRUTH, TRUTH, *option, "--json", str(out)])
    assert got.exit_code == 2 and isinstance(got.exception, SystemExit), got.output
    errors = got.stderr.splitlines()
    assert len(errors) == 1 and errors[0].startswith("pcmapq: error: "), got.stderr
    assert option[0] in errors[0], got.stderr
    assert "Traceback" not in got.stderr and not out.exists()


@pytest.mark.unit
def test_map_voxel_must_be_finite(tmp_path: Path):
    got = CliRunner().invoke(app, ["map", str(tmp_path), "--out", str(tmp_path / "m.ply"),
                                   "--voxel", "inf"])
    assert got.exit_code == 2 and "--voxel" in got.stderr and "finite" in got.stderr


def test_json_is_strict(tmp_path: Path):
    """A NaN that reached the result is a ValueError, never bare NaN in the file."""
    got = CliRunner().invoke(app, ["eval", TRUTH, TRUTH, "--no-align", "--json", "-"])
    assert got.exit_code == 0, got.stderr
    result = Result.from_json(got.stdout)
    assert json.loads(result.to_json()) == json.loads(got.stdout)
    for bad in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="JSON compliant"):
            replace(result, settings={"threshold": bad}).to_json()
