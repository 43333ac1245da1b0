"""What the terminal shows: the verdict, the tables within the console's width, counts that
give back the scores, the vectors CSV's rows, lines broken between values only (the help,
--version, --quiet and 'wrote PATH': tests/cli/test_terminal.py)."""

from __future__ import annotations

import copy
import csv
import io
import json

import pytest
from rich.console import Console

import pcmapq
from pcmapq.report.table import DISPLACEMENT_COLUMNS, print_table
from pcmapq.report.text import verdict, words, wrap
from pcmapq.results.result import Result
from testkit.paths import REPO

#: A stored result of the sample (tests/test_reference.py keeps it current).
SAMPLE_DOC = json.loads((REPO / "tests" / "reference" / "sample.json").read_text())


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
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.split()[:2] == ["detector", "quality"])
    for line in lines[start:]:
        cells = line.split()
        if cells[:1] and cells[0] in SAMPLE_DOC["detectors"]:
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
    assert set(rows) == {"harris", "hough", "sift", "rooms"}
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
        assert f"{name} {det['quality']:.2f}/{det['precision']:.2f}" in first
    assert f"map walls {doc['distances']['accuracy_m']['mean']:.3f} m from the truth's" in first
    assert (f"truth walls {doc['distances']['completeness_m']['mean']:.3f} m from the map's"
            in first)


def test_the_verdict_says_why_a_map_no_pose_fits_is_the_truths_place():
    """Scored as the truth's place with too few parts agreeing, the first line says that its
    pose stands out; with enough parts agreeing, it counts them alone."""
    doc = copy.deepcopy(SAMPLE_DOC)
    part = {"share": 0.125, "centre_m": [1.0, 2.0], "offset_m": 0.1, "turn_deg": 1.0,
            "fitness": 0.5, "agrees": True, "pose": {"x_m": 0.0, "y_m": 0.0, "yaw_deg": 0.0,
                                                     "scale": 1.0}}
    far = {**part, "offset_m": 20.0, "agrees": False}
    doc["alignment"].update(confidence=0.28, verdict="same place, inconsistent map",
                            distinctiveness=0.42, parts=[part] * 2 + [far] * 6)
    line = verdict(sample_result(doc))
    assert ("no single pose fits (confidence 0.28; its pose stands out in the search by 0.42; "
            "2 of its 8 parts placed on their own land near its pose)") in line
    doc["alignment"]["parts"] = [part] * 3 + [far] * 5
    line = verdict(sample_result(doc))
    assert "(confidence 0.28; 3 of its 8 parts placed on their own land near its pose)" in line


def test_the_verdict_says_plainly_when_a_score_is_undefined():
    doc = copy.deepcopy(SAMPLE_DOC)
    doc["detectors"]["harris"].update(quality=None, f1=None, truth_features=0, matched=0)
    doc["missing"] = [m for m in doc["missing"] if m["detector"] != "harris"]
    for m in doc["matches"]:
        m["counted"]["truth"] = m["counted"]["truth"] and m["detector"] != "harris"
    doc["alignment"]["confidence"] = 0.3
    doc["alignment"]["verdict"] = "another place"
    line = verdict(sample_result(doc))
    precision = doc["detectors"]["harris"]["precision"]
    assert f"harris n/a/{precision:.2f} (no strong truth feature inside the footprint)" in line
    assert "it may show another place (confidence 0.30 < 0.5, scored because of --force)" in line
    assert "harris: n/a: no strong truth feature inside the footprint" in shown(
        sample_result(doc), 80)


def test_the_first_line_gives_the_precision_of_a_map_full_of_extra_features():
    """A map that finds a sixth of the truth's corners among 200 of its own (a SLAM map of a
    Gazebo world, precision 0.005) reads low on the first line, not 'harris 0.17' alone."""
    doc = copy.deepcopy(SAMPLE_DOC)
    doc["detectors"]["harris"].update(quality=1 / 6, precision=0.005, f1=0.0097,
                                      map_features=200, matched_map=1)
    line = verdict(sample_result(doc))
    assert "feature quality/precision harris 0.17/0.01," in line


def test_a_detector_with_nothing_to_find_reads_n_a_with_why():
    """One room each side (an outdoor pair): 'rooms n/a (...)', not 'rooms 0.00'; the why
    comes back from the saved JSON."""
    doc = copy.deepcopy(SAMPLE_DOC)
    why = "the truth has 1 room, fewer than 2: nothing to find"
    doc["detectors"]["rooms"].update(quality=None, precision=None, f1=None, note=why,
                                     truth_features=1, map_features=1, matched=0,
                                     matched_map=0)
    result = sample_result(doc)
    assert f"rooms n/a ({why})" in verdict(result)
    assert result.to_dict()["detectors"]["rooms"]["note"] == why


def test_the_regions_line_counts_in_words_and_rounds_the_tile_as_metres():
    """'44 regions of 6.6 m', not '6.64829 m'; one region is 'a region', not '1 regions'."""
    doc = copy.deepcopy(SAMPLE_DOC)
    doc["consistency"]["tile_m"] = 6.64829
    text = " ".join(shown(sample_result(doc), 132).split())
    regions = len(doc["consistency"]["regions"])
    assert f"{regions} regions of 6.6 m" in text and "6.64829" not in text
    doc["consistency"]["regions"] = doc["consistency"]["regions"][:1]
    first = doc["consistency"]["regions"][0]
    doc["consistency"]["largest_at_m"] = [first["x_m"], first["y_m"]]
    text = " ".join(shown(sample_result(doc), 132).split())
    assert "1 region of 6.6 m" in text


def test_the_3d_map_line_gives_awd_and_scs_only_when_the_result_has_them():
    assert "AWD" not in shown(sample_result(), 132)
    doc = copy.deepcopy(SAMPLE_DOC)
    doc["map_3d"] = {"computed_on": "3 m voxels", "voxels": 812, "awd_m": 0.0523, "scs": None}
    doc["settings"]["map_3d"] = {"voxel": 3.0, "min_points": 100, "radius": 5}
    text = " ".join(shown(sample_result(doc), 132).split())
    assert "3D map AWD 0.052 m, SCS -, over 812 voxels of 3 m" in text


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
