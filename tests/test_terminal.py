"""What the terminal shows: the verdict, the tables within the console's width, counts that
give back the scores, the vectors CSV's rows, the help, --version, --quiet and 'wrote PATH'."""

from __future__ import annotations

import copy
import csv
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console
from typer.testing import CliRunner

import pcmapq
from pcmapq.cli import app
from pcmapq.report.table import DISPLACEMENT_COLUMNS, print_table
from pcmapq.report.text import verdict, words, wrap
from pcmapq.results.result import Result

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "data" / "sample"
#: A stored result of the sample (tests/test_reference.py keeps it current).
SAMPLE_DOC = json.loads((ROOT / "tests" / "reference" / "sample.json").read_text())


def sample_result(doc: dict | None = None) -> Result:
    """The stored sample result (or ``doc``, a changed copy of it) read back."""
    doc = copy.deepcopy(SAMPLE_DOC if doc is None else doc)
    doc.setdefault("pcmapq", {"version": pcmapq.__version__, "command": None})
    return Result.from_json(json.dumps(doc))


def shown(result: Result, width: int) -> str:
    """What print_table writes on a console ``width`` columns wide (not a terminal)."""
    buf = io.StringIO()
    print_table(result, Console(file=buf, width=width))
    return buf.getvalue()


def score_rows(text: str) -> dict[str, list[str]]:
    """The score table's row of each detector: its cells, split at spaces."""
    rows: dict[str, list[str]] = {}
    for line in text.splitlines():
        cells = line.split()
        if cells[:1] in (["harris"], ["hough"], ["sift"]):
            rows.setdefault(cells[0], cells[1:])
    return rows


@pytest.mark.parametrize("width", [80, 100, 132])
def test_every_line_fits_and_no_value_is_cut(width):
    text = shown(sample_result(), width)
    assert max(len(line) for line in text.splitlines()) <= width
    assert "…" not in text
    # every figure is printed whole: the scores, the counts and the displacement statistics
    for name, det in SAMPLE_DOC["detectors"].items():
        q, p, f1, *counts = score_rows(text)[name]
        assert (float(q), float(p), float(f1)) == pytest.approx(
            (det["quality"], det["precision"], det["f1"]), abs=5e-4)
        assert [int(c) for c in counts] == [det["truth_features"], det["matched"],
                                            det["map_features"], det["matched_map"]]
        disp = det["displacement_m"]
        row = next(line.split()[1:] for line in text.splitlines()
                   if line.split()[:2] == [name, str(disp["count"])])
        assert [float(v) for v in row[1:]] == pytest.approx(
            [disp[k] for k in DISPLACEMENT_COLUMNS[1:]], abs=5e-4)
    d = SAMPLE_DOC["distances"]
    assert f"mean {d['accuracy_m']['mean']:.3f} m" in text
    assert f"mean {d['completeness_m']['mean']:.3f} m" in text
    assert "docs/metrics.md" in text  # the legend's pointer


def test_quality_and_precision_come_back_from_the_printed_counts():
    """quality = matched truth / truth features, precision = matched map / map features, as
    printed (the sample's Harris has 35 truth matches but 33 map ones: one count cannot give
    both)."""
    rows = score_rows(shown(sample_result(), 80))
    assert set(rows) == {"harris", "hough", "sift"}
    for q, p, _, truth, matched, map_, matched_map in rows.values():
        assert float(q) == pytest.approx(int(matched) / int(truth), abs=5e-4)
        assert float(p) == pytest.approx(int(matched_map) / int(map_), abs=5e-4)
    q, p, _, truth, matched, map_, matched_map = rows["harris"]
    assert (matched, matched_map) == ("35", "33")


def test_a_narrow_console_gets_one_block_per_detector():
    text = shown(sample_result(), 50)
    assert "…" not in text and max(len(line) for line in text.splitlines()) <= 50
    det = SAMPLE_DOC["detectors"]["harris"]
    assert (f"quality {det['quality']:.3f} ({det['matched']}/{det['truth_features']} truth)"
            in text)
    assert (f"precision {det['precision']:.3f} ({det['matched_map']}/{det['map_features']} "
            "map)" in text)


def test_the_first_line_says_how_good_the_map_is_and_why():
    doc = SAMPLE_DOC
    text = shown(sample_result(), 80)
    first = text.split("\n\n")[0].replace("\n", " ")
    assert first == verdict(sample_result())
    assert first.startswith("scan.ply: aligned with confidence 1.00; ")
    assert f"{100 * doc['coverage']:.0f} % of the truth's walls covered" in first
    for name, det in doc["detectors"].items():
        assert f"{name} {det['quality']:.2f}" in first
    assert f"map walls {doc['distances']['accuracy_m']['mean']:.3f} m from the truth's" in first
    assert (f"truth walls {doc['distances']['completeness_m']['mean']:.3f} m from the map's"
            in first)


def test_the_verdict_says_plainly_when_a_score_is_undefined():
    doc = copy.deepcopy(SAMPLE_DOC)
    doc["detectors"]["harris"].update(quality=None, f1=None, truth_features=0, matched=0)
    doc["missing"] = [m for m in doc["missing"] if m["detector"] != "harris"]
    for m in doc["matches"]:
        m["counted"]["truth"] = m["counted"]["truth"] and m["detector"] != "harris"
    doc["alignment"]["confidence"] = 0.3
    doc["alignment"]["verdict"] = "another place"
    line = verdict(sample_result(doc))
    assert "harris n/a (no strong truth feature inside the footprint)" in line
    assert "it may show another place (confidence 0.30 < 0.5, scored because of --force)" in line
    assert "harris: n/a: no strong truth feature inside the footprint" in shown(
        sample_result(doc), 80)


def test_lines_break_between_values_only():
    assert wrap(["x 6.016 m", "y 7.985 m", "yaw 36.99 deg"], 21) == [
        "x 6.016 m, y 7.985 m,", "yaw 36.99 deg"]
    assert wrap(["a much longer value than the line"], 10) == [
        "a much longer value than the line"]
    # a number stays with its unit
    assert words("walls 0.127 m from it; 97 % of 36.99 deg", 12) == [
        "walls", "0.127 m from", "it; 97 % of", "36.99 deg"]


def test_vectors_csv_rows_are_the_pairs_and_say_which_features_count():
    result = sample_result()
    rows = list(csv.DictReader(io.StringIO(result.vectors_csv())))
    assert len(rows) == len(SAMPLE_DOC["matches"])
    for name, det in SAMPLE_DOC["detectors"].items():
        mine = [r for r in rows if r["detector"] == name]
        assert len(mine) == det["displacement_m"]["count"]
        assert sum(int(r["truth_counted"]) for r in mine) == det["matched"]
        assert sum(int(r["map_counted"]) for r in mine) == det["matched_map"]
    # the sample's Harris pairs two map features that are not counted (precision 33/40)
    assert sum(r["detector"] == "harris" and r["map_counted"] == "0" for r in rows) == 2


def test_version():
    got = CliRunner().invoke(app, ["--version"])
    assert got.exit_code == 0 and got.stdout == f"pcmapq {pcmapq.__version__}\n"


def test_help_shows_defaults_choices_and_no_bool_placeholder():
    got = CliRunner().invoke(app, ["eval", "--help"])
    text = got.stdout
    assert got.exit_code == 0
    assert "<bool>" not in text
    flat = re.sub(r"\s+", " ", text)
    assert "occupied (default: 2 for a 3D cloud, 1 for a 2D one)" in flat
    assert "[default: 0.5; x>=1e-06]" in flat and "[default: harris,hough,sift]" in flat
    assert "--scale <fixed|auto>" in text and "--footprint <auto|known|walls|all>" in text
    assert "-q, --quiet" in text


@pytest.mark.parametrize("columns", [80, 120])
def test_help_is_as_wide_as_the_terminal(columns):
    """Click alone stops at 80 columns; the help uses the terminal's width, and no more."""
    env = {**os.environ, "COLUMNS": str(columns)}
    got = subprocess.run([sys.executable, "-m", "pcmapq", "eval", "--help"], env=env,
                         capture_output=True, text=True, timeout=120)
    assert got.returncode == 0, got.stderr
    assert columns - 10 < max(len(line) for line in got.stdout.splitlines()) <= columns


def test_quiet_prints_nothing_and_every_output_file_is_announced(tmp_path):
    args = ["eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"), "--detectors",
            "hough"]
    out = {"--json": tmp_path / "r.json", "--vectors": tmp_path / "v.csv"}
    files = [w for opt, path in out.items() for w in (opt, str(path))]
    loud = CliRunner().invoke(app, [*args, *files], env={"COLUMNS": "80"})
    assert loud.exit_code == 0, loud.stderr
    assert loud.stderr.splitlines() == [f"wrote {out['--json']}", f"wrote {out['--vectors']}"]
    assert loud.stdout.startswith("scan.ply: aligned")
    assert max(len(line) for line in loud.stdout.splitlines()) <= 80
    for path in out.values():
        path.unlink()
    quiet = CliRunner().invoke(app, [*args, *files, "--quiet"])
    assert quiet.exit_code == 0 and quiet.stdout == "" and quiet.stderr == ""
    assert all(path.exists() for path in out.values())


def test_map_says_what_it_wrote_unless_quiet(tmp_path):
    """`pcmapq map` with given poses on two small scans: one 'wrote PATH' line per file."""
    scans = tmp_path / "scans"
    scans.mkdir()
    rng = np.random.default_rng(0)
    for k in range(2):
        np.save(scans / f"{k:06d}.npy", rng.uniform(-5, 5, (500, 3)))
    poses = tmp_path / "poses.txt"
    poses.write_text("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n")
    out = [tmp_path / "m.ply", tmp_path / "kitti.txt", tmp_path / "tum.txt"]
    args = ["map", str(scans), "--poses", str(poses), "--out", str(out[0]), "--poses-out",
            str(out[1]), "--tum-out", str(out[2])]
    loud = CliRunner().invoke(app, args)
    assert loud.exit_code == 0, loud.stderr
    lines = loud.stderr.splitlines()
    assert [line.split(":")[0] for line in lines] == [f"wrote {path}" for path in out]
    assert lines[1].endswith(": 2 poses (KITTI)") and lines[2].endswith(": 2 poses (TUM)")
    quiet = CliRunner().invoke(app, [*args, "-q"])
    assert quiet.exit_code == 0 and quiet.stdout == "" and quiet.stderr == ""
