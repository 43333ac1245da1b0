"""The command line: outputs, exit codes and one-line errors."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import numpy as np
import pytest

import pcmapq
from pcmapq.settings import Settings
from testkit.command import run, run_process
from testkit.files import write_image_map
from testkit.paths import SAMPLE


@pytest.fixture(scope="module")
def sample_json(tmp_path_factory) -> tuple[dict, Path, Path]:
    out = tmp_path_factory.mktemp("out")
    before = {p: p.read_bytes() for p in SAMPLE.rglob("*") if p.is_file()}
    proc = run("eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"),
               "--json", str(out / "r.json"), "--vectors", str(out / "v.csv"),
               "--plot", str(out / "p.png"), "--report", str(out / "r.html"))
    assert proc.returncode == 0, proc.stderr
    assert {p: p.read_bytes() for p in SAMPLE.rglob("*") if p.is_file()} == before  # untouched
    assert (out / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "r.html").read_text().startswith("<!DOCTYPE html>")
    assert sorted(p.name for p in out.iterdir()) == ["p.png", "r.html", "r.json", "v.csv"]
    assert "harris" in proc.stdout and "quality" in proc.stdout
    return json.loads((out / "r.json").read_text()), out / "r.json", out / "v.csv"


def test_sample_json_has_the_documented_fields(sample_json):
    doc, _, _ = sample_json
    assert {"map", "truth", "alignment", "detectors", "matches", "missing", "extra"} <= set(doc)
    assert doc["map"]["kind"] == "cloud" and doc["truth"]["kind"] == "image"
    assert doc["truth"]["resolution_m"] == 0.05
    a = doc["alignment"]
    assert {"x_m", "y_m", "yaw_deg", "scale", "matrix", "fitness", "rmse_m"} <= set(a)
    # tools/make_sample.py places the scan frame at x 6, y 8, yaw 37 degrees in the truth frame
    assert abs(a["x_m"] - 6.0) < 0.1 and abs(a["y_m"] - 8.0) < 0.1
    assert abs(a["yaw_deg"] - 37.0) < 0.5
    for name in ("harris", "hough", "sift"):
        det = doc["detectors"][name]
        assert {"quality", "precision", "f1", "truth_features", "map_features", "matched",
                "threshold_m", "displacement_m"} <= set(det)
        # matched counts the matched truth features above the detection threshold; the matches
        # list also holds pairs where only the map side is above it (see docs/method.md)
        assert det["matched"] <= sum(m["detector"] == name for m in doc["matches"])
        assert det["quality"] == round(det["matched"] / det["truth_features"], 6)
        assert 0.5 < det["quality"] <= 1.0


def test_vectors_csv_has_one_row_per_match(sample_json):
    doc, _, csv = sample_json
    lines = csv.read_text().splitlines()
    assert lines[0].startswith("detector,truth_x_m,truth_y_m,map_x_m,map_y_m")
    assert len(lines) - 1 == len(doc["matches"])


def test_json_is_byte_identical_between_runs(sample_json):
    first, _, _ = sample_json
    args = ("eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"), "--json", "-")
    runs = [run_process(*args) for _ in range(2)]  # two interpreters, two hash seeds
    assert all(p.returncode == 0 for p in runs), runs[0].stderr
    assert runs[0].stdout == runs[1].stdout  # also: nothing but the JSON on stdout
    again = json.loads(runs[0].stdout)
    # the same result as the first run's, which wrote its outputs elsewhere: only its command
    # line differs
    assert again["pcmapq"]["command"] == shlex.join(["pcmapq", *args])
    assert {k: v for k, v in again.items() if k != "pcmapq"} == {
        k: v for k, v in first.items() if k != "pcmapq"}


def test_json_says_how_it_was_made(sample_json):
    doc, _, _ = sample_json
    assert doc["pcmapq"]["version"] == pcmapq.__version__
    assert doc["pcmapq"]["command"].startswith("pcmapq eval ")
    assert "--json" in doc["pcmapq"]["command"] and "--threshold" not in doc["pcmapq"]["command"]
    # a 2D pair: no figures of two 3D clouds, nor the settings that only they take
    assert "map_3d" not in doc and "structures_3d" not in doc
    assert doc["settings"] == json.loads(json.dumps(
        {k: v for k, v in Settings().to_dict().items() if k not in ("map_3d", "structures")}))


@pytest.mark.parametrize("case", ["missing", "garbage_png", "yaml_without_resolution",
                                  "png_without_resolution", "unsupported"])
def test_bad_input_exits_2_with_one_line(case, tmp_path):
    truth = str(SAMPLE / "truth.png")
    if case == "missing":
        bad = tmp_path / "nope.ply"
    elif case == "garbage_png":
        bad = tmp_path / "junk.png"
        bad.write_bytes(b"not an image at all")
        (tmp_path / "junk.yaml").write_text("image: junk.png\nresolution: 0.05\norigin: [0,0,0]\n")
    elif case == "yaml_without_resolution":
        bad = tmp_path / "m.yaml"
        bad.write_text("image: truth.png\norigin: [0, 0, 0]\n")
        (tmp_path / "truth.png").write_bytes((SAMPLE / "truth.png").read_bytes())
    elif case == "png_without_resolution":
        bad = tmp_path / "plain.png"
        bad.write_bytes((SAMPLE / "truth.png").read_bytes())
    else:
        bad = tmp_path / "map.abc"
        bad.write_text("1 2 3\n")
    proc = run("eval", str(bad), truth)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and bad.name in lines[0], proc.stderr


def test_map_of_another_place_exits_1_unless_forced(tmp_path):
    ring = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    rooms = []  # another place: three round rooms, nothing like the sample's building
    for cx, cy, r in ((6, 6, 5), (16, 8, 4), (11, 15, 3)):
        p = np.column_stack([cx + r * np.cos(ring), cy + r * np.sin(ring)])
        rooms.append(np.hstack([p, np.roll(p, -1, axis=0)]))
    other = write_image_map(np.vstack(rooms), tmp_path / "other.png")
    proc = run("eval", str(other), str(SAMPLE / "truth.png"))
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr and "other.png" in proc.stderr
    forced = run("eval", str(other), str(SAMPLE / "truth.png"), "--force", "--json", "-")
    assert forced.returncode == 0
    assert json.loads(forced.stdout)["alignment"]["confidence"] < 0.5


def test_init_and_no_align(tmp_path):
    """--no-align scores the map where it stands; --init starts ICP from a guess; a malformed
    --init is a usage error (exit 2)."""
    truth = str(SAMPLE / "truth.png")
    still = run("eval", truth, truth, "--no-align", "--json", "-")
    assert still.returncode == 0, still.stderr
    a = json.loads(still.stdout)["alignment"]
    assert (a["x_m"], a["y_m"], a["yaw_deg"], a["method"]) == (0.0, 0.0, 0.0, "none")
    guided = run("eval", str(SAMPLE / "scan.ply"), truth, "--init", "6.2,7.9,36", "--json", "-")
    assert guided.returncode == 0, guided.stderr
    a = json.loads(guided.stdout)["alignment"]
    assert a["method"] == "init+icp" and abs(a["yaw_deg"] - 37.0) < 0.5
    assert run("eval", truth, truth, "--init", "1,2").returncode == 2


def test_map_command_bad_input_exits_2(tmp_path):
    proc = run("map", str(tmp_path / "none"), "--out", str(tmp_path / "m.ply"))
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "none" in lines[0], proc.stderr


def test_memory_guard_stops_before_the_work(tmp_path):
    """A run estimated past --max-memory stops with exit 2 and one line saying how much it needs
    and what needs less; nothing is written."""
    out = tmp_path / "r.json"
    proc = run("eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"), "--max-memory",
               "0.1", "--json", str(out))
    assert proc.returncode == 2 and not out.exists()
    line, = proc.stderr.strip().splitlines()
    assert "needs about 0.5 GB of memory, more than the limit of 0.1 GB" in line
    # the libraries alone take more than 0.1 GB: only a higher limit helps
    assert "a --max-memory of 0.5 GB or more runs it" in line
    assert "--truth-resolution" not in line and "Traceback" not in proc.stderr


def test_margin_grows_the_part_of_the_truth_a_partial_map_is_scored_against():
    """--margin (an option added by its line in the option table alone): a partial map (the
    sample cut at x = 8 m) is scored against more truth features with a wider margin around
    its footprint, so its quality cannot rise; the JSON and the command line record it."""
    def scored(margin: str) -> dict:
        proc = run("eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"), "--map-crop",
                   "-100,-100,8,100", "--detectors", "harris", "--no-noref", "--margin", margin,
                   "--json", "-")
        assert proc.returncode == 0, proc.stderr
        return json.loads(proc.stdout)

    narrow, wide = scored("0"), scored("2")
    assert (narrow["settings"]["footprint"]["margin"], wide["settings"]["footprint"]["margin"]) \
        == (0.0, 2.0)
    assert "--margin 2.0" in wide["pcmapq"]["command"]
    n, w = narrow["detectors"]["harris"], wide["detectors"]["harris"]
    assert w["truth_features"] > n["truth_features"] and w["quality"] <= n["quality"]
