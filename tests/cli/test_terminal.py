"""What the terminal shows of a command: --version, the help (defaults, choices, as wide as the
terminal), --quiet and 'wrote PATH'."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest
from typer.testing import CliRunner

import pcmapq
from pcmapq.cli import app
from testkit.paths import SAMPLE


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
    assert "[default: 0.5; x>=1e-06]" in flat and "[default: harris,hough,sift,rooms]" in flat
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
