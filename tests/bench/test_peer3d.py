"""The CloudAnalyzer case of ``python -m bench`` (``--only peer3d``, :mod:`bench.bench_peer3d`)
where CloudAnalyzer is not installed: one line saying so, no ratio, exit 0. Tests reach bench/
only through its command lines, in a subprocess."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from testkit.paths import REPO


@pytest.mark.parametrize("command", [["bench", "--only", "peer3d"], ["bench.bench_peer3d"]])
def test_without_cloudanalyzer_the_case_is_skipped_with_one_line(tmp_path: Path,
                                                                 command: list[str]) -> None:
    got = subprocess.run([sys.executable, "-m", *command, "--cache", str(tmp_path)], cwd=REPO,
                         capture_output=True, text=True, timeout=120,
                         env={"PATH": str(tmp_path), "PYTHONPATH": str(REPO / "src")})
    assert got.returncode == 0, got.stderr
    assert ("peer3d: skipped, CloudAnalyzer's `ca` is not on the PATH (pip install "
            "cloudanalyzer, in a virtual environment of its own: bench/bench_peer3d.py)"
            ) in got.stderr
    assert "peer3d/" not in got.stdout  # no ratio measured
    assert not any(tmp_path.iterdir())  # nor the pair written
