"""`pcmapq inspect --radius` (a former name, docs/commands/inspect.md): one warning line, then the
same run and the same bytes as `--noref-radius`, whose name the saved command line carries."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app

TRUTH = Path(__file__).resolve().parents[2] / "data" / "sample" / "truth.yaml"


@pytest.mark.unit
def test_a_former_name_warns_once_and_gives_the_same_json():
    old = CliRunner().invoke(app, ["inspect", str(TRUTH), "--radius", "0.3", "--crop",
                                   "-5,-5,5,5", "--json", "-"])
    new = CliRunner().invoke(app, ["inspect", str(TRUTH), "--noref-radius", "0.3",
                                   "--map-crop", "-5,-5,5,5", "--json", "-"])
    assert old.exit_code == new.exit_code == 0, old.stderr + new.stderr
    assert old.stderr.splitlines() == ["pcmapq: warning: --crop is renamed --map-crop",
                                       "pcmapq: warning: --radius is renamed --noref-radius"]
    assert new.stderr == "" and old.stdout == new.stdout
    command = json.loads(old.stdout)["pcmapq"]["command"]
    assert command.endswith("--json - --map-crop -5,-5,5,5 --noref-radius 0.3")


@pytest.mark.unit
def test_a_former_name_refused_names_the_problem_in_one_line():
    got = CliRunner().invoke(app, ["inspect", str(TRUTH), "--radius", "0.3", "--noref-radius",
                                   "0.2"])
    assert got.exit_code == 2 and got.stderr.count("\n") == 1, got.stderr
    assert got.stderr.startswith("pcmapq: error: invalid value for --noref-radius: give it "
                                 "once (--radius is its former name)")
