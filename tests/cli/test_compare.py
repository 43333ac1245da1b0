"""``pcmapq compare``: saved results side by side, refusing results of different truths unless
told, one-line errors naming a file that is not a result."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

from testkit import synth
from testkit.command import run
from testkit.files import write_image_map
from testkit.paths import SAMPLE


@pytest.fixture(scope="module")
def saved(plan, truth_png, tmp_path_factory) -> dict[str, Path]:
    """Result JSONs written by ``pcmapq eval --json``: the sample ('a'); the sample scored by
    harris and sift only ('b', same truth, hough null); a synthetic map with a third of its
    walls dropped against the synthetic plan ('other', another truth)."""
    out = tmp_path_factory.mktemp("saved")
    degraded = write_image_map(synth.drop_walls(plan, 0.3, seed=1), out / "degraded.png")
    jobs = {"a": [str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.yaml")],
            "b": [str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.yaml"),
                  "--detectors", "harris,sift"],
            "other": [str(degraded), str(truth_png)]}
    for name, args in jobs.items():
        proc = run("eval", *args, "--json", str(out / f"{name}.json"), "--quiet")
        assert proc.returncode == 0, proc.stderr
    return {name: out / f"{name}.json" for name in jobs}


def table(folder: Path) -> list[dict[str, str]]:
    with open(folder / "table.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_compare_writes_one_row_per_result(saved, tmp_path):
    proc = run("compare", str(saved["a"]), str(saved["b"]), "--out", str(tmp_path / "cmp"))
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in (tmp_path / "cmp").iterdir()) == \
        ["figure.png", "table.csv", "table.md"]
    rows = table(tmp_path / "cmp")
    assert [r["name"] for r in rows] == ["a", "b"]
    docs = [json.loads(saved[n].read_text()) for n in ("a", "b")]
    for row, doc in zip(rows, docs, strict=True):
        assert float(row["sift_quality"]) == doc["detectors"]["sift"]["quality"]
        assert float(row["accuracy_mean_m"]) == doc["distances"]["accuracy_m"]["mean"]
        assert row["truth"] == doc["truth"]["path"]
    assert rows[0]["hough_quality"] != "" and rows[1]["hough_quality"] == ""
    shown = {line.split()[0]: line.split()[1:] for line in proc.stdout.splitlines()
             if line.split()[:1] in (["a"], ["b"])}  # the table on the terminal
    assert sorted([shown["a"][0], shown["b"][0]]) == ["1", "2"]  # their ranks
    assert shown["a"][1:4] == [f"{d['detectors'][k]['quality']:.3f}" for d in docs[:1]
                               for k in ("harris", "hough", "sift")]
    assert shown["b"][2] == "n/a" and shown["b"][-1] == "ok"
    assert proc.stderr.count("wrote ") == 3
    assert f"wrote {tmp_path / 'cmp' / 'table.csv'}\n" in proc.stderr  # as --out was given


def test_wrote_lines_give_the_paths_as_typed(saved, tmp_path, monkeypatch):
    """eval and compare both name what they wrote as the user typed it (compare gave the
    resolved absolute path)."""
    monkeypatch.chdir(tmp_path)
    proc = run("compare", str(saved["a"]), str(saved["b"]), "--out", "cmp")
    assert proc.returncode == 0, proc.stderr
    assert [line for line in proc.stderr.splitlines() if line.startswith("wrote ")] == \
        ["wrote cmp/table.csv", "wrote cmp/table.md", "wrote cmp/figure.png"]


def test_names_replace_the_file_stems(saved, tmp_path):
    proc = run("compare", str(saved["a"]), str(saved["b"]), "--names", "full,two",
               "--out", str(tmp_path), "-q")
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "", "")
    assert [r["name"] for r in table(tmp_path)] == ["full", "two"]
    proc = run("compare", str(saved["a"]), str(saved["b"]), "--names", "one",
               "--out", str(tmp_path / "x"))
    assert proc.returncode == 2
    assert proc.stderr == "pcmapq: error: --names gives 1 name for 2 results\n"


def test_results_of_different_truths_are_refused_unless_allowed(saved, tmp_path):
    out = tmp_path / "cmp"
    proc = run("compare", str(saved["a"]), str(saved["other"]), "--out", str(out))
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert str(saved["other"]) in proc.stderr and "sha256" in proc.stderr
    assert "--allow-different-truths" in proc.stderr
    assert not out.exists()  # refused before anything is written
    proc = run("compare", str(saved["a"]), str(saved["other"]), "--out", str(out),
               "--allow-different-truths")
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.startswith("pcmapq: warning: 1 of 2 results have another truth")
    assert [r["name"] for r in table(out)] == ["a", "other"]


def test_one_truth_written_two_ways_is_one_truth(saved, tmp_path, monkeypatch):
    """The sample's truth given to eval as typed from its folder ('truth.yaml') and as an
    absolute path (as batch stores it): compare takes them as one truth, by their SHA-256;
    without it (an older result), by the path resolved from the folder compare runs in."""
    monkeypatch.chdir(SAMPLE)
    relative = tmp_path / "relative.json"
    proc = run("eval", "scan.ply", "truth.yaml", "--json", str(relative), "--quiet")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(relative.read_text())
    assert doc["truth"]["path"] == "truth.yaml"
    assert doc["truth"]["sha256"] == json.loads(saved["a"].read_text())["truth"]["sha256"]
    proc = run("compare", str(saved["a"]), str(relative), "--out", str(tmp_path / "cmp"))
    assert proc.returncode == 0 and "another truth" not in proc.stderr, proc.stderr
    for key in ("a", "relative"):
        older = json.loads((saved["a"] if key == "a" else relative).read_text())
        del older["truth"]["sha256"]
        (tmp_path / f"{key}_old.json").write_text(json.dumps(older))
    proc = run("compare", str(tmp_path / "a_old.json"), str(tmp_path / "relative_old.json"),
               "--out", str(tmp_path / "cmp_old"))
    assert proc.returncode == 0 and "another truth" not in proc.stderr, proc.stderr


@pytest.mark.parametrize("content, says", [
    ('{"pcmapq": ', "not a JSON file"),
    (b"\xff\xfe", "not a JSON file"),
    ("[1, 2]", "not a pcmapq eval result"),
    ('{"pcmapq": {}, "map": {"path": "m"}}', "not a pcmapq eval result: no 'settings'"),
])
def test_a_file_that_is_not_a_result_is_one_line_exit_2(saved, tmp_path, content, says):
    bad = tmp_path / "bad.json"
    (bad.write_bytes if isinstance(content, bytes) else bad.write_text)(content)
    proc = run("compare", str(saved["a"]), str(bad), "--out", str(tmp_path / "cmp"))
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"pcmapq: error: {bad}: {says}")
    assert proc.stderr.count("\n") == 1
    assert not (tmp_path / "cmp").exists()


def test_a_result_missing_a_figure_is_named(saved, tmp_path):
    doc = json.loads(saved["a"].read_text())
    del doc["distances"]["chamfer_m"]
    bad = tmp_path / "nochamfer.json"
    bad.write_text(json.dumps(doc))
    proc = run("compare", str(bad), "--out", str(tmp_path / "cmp"))
    assert (proc.returncode, proc.stderr) == (
        2, f"pcmapq: error: {bad}: not a pcmapq eval result: no 'distances.chamfer_m'\n")
    proc = run("compare", str(tmp_path / "absent.json"), "--out", str(tmp_path / "cmp"))
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"pcmapq: error: {tmp_path / 'absent.json'}: cannot read")


def test_the_same_results_give_the_same_bytes_in_another_process(saved, tmp_path):
    args = [str(saved["a"]), str(saved["b"]), str(saved["other"]),
            "--allow-different-truths", "-q"]
    assert run("compare", *args, "--out", str(tmp_path / "one")).returncode == 0
    proc = subprocess.run([sys.executable, "-m", "pcmapq", "compare", *args,
                           "--out", str(tmp_path / "two")], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    for name in ("table.csv", "table.md", "figure.png"):
        assert (tmp_path / "one" / name).read_bytes() == (tmp_path / "two" / name).read_bytes()


def test_alike_file_stems_are_named_by_their_paths(saved, tmp_path):
    (tmp_path / "again").mkdir()
    copy = tmp_path / "again" / "a.json"
    copy.write_bytes(saved["a"].read_bytes())
    proc = run("compare", str(saved["a"]), str(copy), "--out", str(tmp_path / "cmp"), "-q")
    assert proc.returncode == 0, proc.stderr
    assert [r["name"] for r in table(tmp_path / "cmp")] == \
        [str(saved["a"].with_suffix("")), str(copy.with_suffix(""))]


def test_a_batch_result_and_an_eval_result_share_their_truth(saved, tmp_path):
    """batch stores the truth's path absolute and takes its SHA-256 from the row's key; eval's
    result of the same truth is one truth with it."""
    proc = run("batch", str(SAMPLE / "scan.ply"), "--truth", str(SAMPLE / "truth.yaml"),
               "--out", str(tmp_path / "b"), "--quiet")
    assert proc.returncode == 0, proc.stderr
    batch_doc = json.loads((tmp_path / "b" / "scan.json").read_text())
    assert batch_doc["truth"]["sha256"] == json.loads(saved["a"].read_text())["truth"]["sha256"]
    proc = run("compare", str(saved["a"]), str(tmp_path / "b" / "scan.json"), "--out",
               str(tmp_path / "cmp"))
    assert proc.returncode == 0 and "another truth" not in proc.stderr, proc.stderr
    assert "other settings" not in proc.stderr, proc.stderr  # batch scores as eval does


def test_results_scored_with_other_settings_are_compared_with_a_warning_naming_them(
        saved, tmp_path):
    """The sample scored again with a 0.3 m match threshold, and a result saved before a
    setting was one (its record lacks the footprint's margin): one warning line names each
    setting that differs, its values and their files; the table is written all the same.
    Only the detectors run ('a' against 'b') is no difference."""
    proc = run("eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.yaml"), "--threshold",
               "0.3", "--json", str(tmp_path / "t.json"), "--quiet")
    assert proc.returncode == 0, proc.stderr
    old = json.loads(saved["a"].read_text())
    del old["settings"]["footprint"]["margin"]
    (tmp_path / "old.json").write_text(json.dumps(old))
    proc = run("compare", str(saved["a"]), str(tmp_path / "t.json"), str(tmp_path / "old.json"),
               "--out", str(tmp_path / "cmp"))
    assert proc.returncode == 0, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if "other settings" in ln]
    assert len(lines) == 1, proc.stderr
    assert f"matching.threshold (0.5 in {saved['a']}, {tmp_path / 'old.json'}; 0.3 in " \
        f"{tmp_path / 't.json'})" in lines[0], lines[0]
    assert f"footprint.margin (0.3 in {saved['a']}, {tmp_path / 't.json'}; not recorded in " \
        f"{tmp_path / 'old.json'})" in lines[0], lines[0]
    assert [r["name"] for r in table(tmp_path / "cmp")] == ["a", "t", "old"]
    proc = run("compare", str(saved["a"]), str(saved["b"]), "--out", str(tmp_path / "ab"))
    assert proc.returncode == 0 and "other settings" not in proc.stderr, proc.stderr
