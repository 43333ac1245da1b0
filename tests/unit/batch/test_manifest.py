"""Batch manifests (pcmapq.batch): rows read from CSV and YAML, options set and maps globbed on the
command line's terms, a row that raises."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import pytest

from pcmapq.batch import Task, read_rows, run_row
from pcmapq.batch.manifest import glob_rows, parse_assignments
from pcmapq.core.errors import InputError
from pcmapq.settings import MatchingConfig, Settings
from testkit.batch import write_inputs


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """A small truth, three maps of it seen from other poses and a map file that is not an
    image, with a manifest naming them (:func:`testkit.batch.write_inputs`)."""
    return write_inputs(tmp_path_factory.mktemp("batch"))


def test_manifest_rows(inputs):
    """Relative paths are the manifest folder's; each row's options give the Settings eval
    builds from the same options, and its eval command line."""
    rows = read_rows(inputs / "runs.csv", {"tau": "0.1,0.2"})
    assert [r.name for r in rows] == ["straight", "turned", "broken", "scaled"]
    assert rows[0].map == inputs / "maps" / "straight.png"
    assert rows[0].truth == inputs / "truth.png"
    assert rows[1].settings.matching == MatchingConfig(threshold=0.3)
    assert rows[3].settings.alignment.scale and rows[3].settings.footprint.rule == "walls"
    assert rows[0].settings.distances.taus == (0.1, 0.2)
    assert rows[0].settings.alignment == Settings().alignment
    assert rows[3].command({"--json": Path("/o/scaled.json")}) == shlex.join(
        ["pcmapq", "eval", str(rows[3].map), str(rows[3].truth), "--json", "/o/scaled.json",
         "--scale", "auto", "--tau", "0.1,0.2", "--footprint", "walls"])


def test_yaml_manifest(inputs, tmp_path):
    """A YAML manifest with defaults: the same rows as the CSV with those cells."""
    doc = {"defaults": {"truth": str(inputs / "truth.png"), "min_hits": 2},
           "rows": [{"map": str(inputs / "maps" / "turned.png"), "threshold": 0.3,
                     "detectors": ["harris", "sift"], "map_negate": False}]}
    (tmp_path / "runs.yaml").write_text(json.dumps(doc))
    (row,) = read_rows(tmp_path / "runs.yaml", {})
    assert row.name == "turned"
    assert row.settings.matching.detectors == ("harris", "sift")
    assert row.settings.raster.min_hits == 2
    assert "--map-no-negate" in row.command({"--json": Path("x.json")})


def test_set_and_glob(inputs, tmp_path, monkeypatch):
    """--set fills every row (its truth from the current folder, a manifest's paths from the
    manifest's); a glob's rows are its maps, sorted, named by stem."""
    (tmp_path / "runs.csv").write_text(f"map\n{inputs / 'maps' / 'turned.png'}\n")
    monkeypatch.chdir(inputs)
    (row,) = read_rows(tmp_path / "runs.csv", parse_assignments(["truth=truth.png"]))
    assert row.truth == inputs / "truth.png"
    rows = glob_rows([str(inputs / "maps" / "s*.png")], inputs / "truth.png",
                     parse_assignments(["threshold=0.25"]))
    assert [r.name for r in rows] == ["scaled", "straight"]
    assert {r.settings.matching.threshold for r in rows} == {0.25}
    with pytest.raises(InputError, match="matches no file"):
        glob_rows([str(inputs / "none*.png")], inputs / "truth.png", {})
    with pytest.raises(InputError, match="--set thresh=1: unknown column"):
        parse_assignments(["thresh=1"])


def test_a_row_that_raises(inputs, tmp_path, monkeypatch):
    """An unexpected exception in a row is the row's failure (exit 1, one line), not the
    batch's."""
    import pcmapq.batch.row as run_module

    def explode(*_args, **_kwargs):
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(run_module, "evaluate", explode)
    row = read_rows(inputs / "runs.csv", {})[0]
    outcome = run_row(Task(row, tmp_path))
    assert (outcome.status, outcome.exit_code, outcome.error) == (
        "failed", 1, "RuntimeError: boom")
    assert outcome.summary["exit_code"] == 1 and outcome.summary["harris_quality"] is None
