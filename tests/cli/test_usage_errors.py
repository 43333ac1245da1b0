"""Usage errors (unknown option or command, bad or missing value) are one line, exit 2."""

from __future__ import annotations

import subprocess
import sys

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from testkit.paths import SAMPLE

MAP, TRUTH = str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.yaml")

#: (arguments, words the one line must hold, the command whose --help it points to)
CASES = [
    (["eval", "--bogus", MAP, TRUTH], "no such option: --bogus", "eval"),
    (["eval", "--thresh", "3", MAP, TRUTH], "did you mean", "eval"),
    (["eval", "--threshold", "abc", MAP, TRUTH], "invalid value for '--threshold'", "eval"),
    (["eval", "--threshold", "-1", MAP, TRUTH], "greater than or equal", "eval"),
    (["eval", MAP, TRUTH, "--detectors"], "option '--detectors' requires an argument", "eval"),
    (["eval", "--no-align=3", MAP, TRUTH], "does not take a value", "eval"),
    (["eval"], "missing argument 'MAP TRUTH'", "eval"),
    (["eval", MAP, TRUTH, MAP], "give MAP and TRUTH", "eval"),
    (["map"], "missing argument", "map"),
    (["map", "--bogus"], "no such option: --bogus", "map"),
    (["map", "somewhere", "--out"], "option '--out' requires an argument", "map"),
    (["bogus"], "no such command 'bogus'", None),
    (["--bogus"], "no such option: --bogus", None),
]


@pytest.mark.parametrize(("args", "words", "command"), CASES, ids=[c[1] for c in CASES])
def test_usage_error_is_one_line_exit_2(args, words, command):
    got = CliRunner().invoke(app, args, prog_name="pcmapq")
    assert got.exit_code == 2, got.output
    assert got.stdout == ""
    lines = got.stderr.splitlines()
    assert len(lines) == 1, got.stderr
    assert lines[0].startswith("pcmapq: error: ") and words in lines[0], lines[0]
    see = "pcmapq --help" if command is None else f"pcmapq {command} --help"
    assert lines[0].endswith(f"(see '{see}')"), lines[0]


def test_help_is_click_s_own():
    """--help, and pcmapq with no arguments, still print the whole help."""
    for args, code in ((["--help"], 0), (["eval", "--help"], 0), ([], 2)):
        got = CliRunner().invoke(app, args, prog_name="pcmapq")
        assert got.exit_code == code
        text = got.stdout + got.stderr
        assert text.startswith("Usage: pcmapq") and "Options:" in text
        assert "error" not in text.lower().split("options:")[0]


def test_module_entry_point_says_one_line():
    """``python -m pcmapq``: the same one line, naming the command as it was typed."""
    proc = subprocess.run([sys.executable, "-m", "pcmapq", "eval", "--bogus"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.splitlines() == [
        "pcmapq: error: no such option: --bogus (see 'python -m pcmapq eval --help')"]
