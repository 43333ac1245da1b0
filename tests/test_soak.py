"""The soak of bench/soak.py in small: a few evaluations in one process leave no thread or file
behind and repeat their first result byte for byte, which is also a fresh process's."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from bench import soak

ROOT = Path(__file__).resolve().parents[1]

SINGLE_RUN = """
import sys
from pcmapq.evaluation.pipeline import evaluate
sys.stdout.write(evaluate(sys.argv[1], sys.argv[2]).to_json())
"""


@pytest.mark.e2e
def test_repeated_evaluations_leak_nothing_and_repeat_their_results(tmp_path: Path) -> None:
    keep = ("sample scan vs truth", "synthetic cloud, moved 5, -3 m, 33 deg",
            "degenerate map (3 identical points)", "missing map file")
    items = [i for i in soak.synthetic_inputs(tmp_path) if i.name in keep]
    assert [i.name for i in items] == list(keep)
    got = soak.soak(items, 2 * len(items))  # 8 evaluations
    assert got.runs == 8 and got.unexpected == [] and got.mismatches == []
    start, warm, end = (got.census[k] for k in ("start", "first round", "end"))
    assert end.python_threads == start.python_threads
    assert end.os_threads <= warm.os_threads and end.fds <= warm.fds
    assert got.first["degenerate map (3 identical points)"].startswith("EvaluationError: ")
    assert got.first["missing map file"].startswith(f"InputError: {tmp_path / 'absent.ply'}")
    # the soak's result is the one a fresh process gives
    sample = items[0]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    fresh = subprocess.run([sys.executable, "-c", SINGLE_RUN, str(sample.map_path),
                            str(sample.truth_path)], capture_output=True, text=True, check=True,
                           env=env).stdout
    assert fresh == got.first[sample.name]


@pytest.mark.unit
def test_soak_failures_name_each_leak() -> None:
    got = soak.Soak(["a", "b"], runs=6, seconds=[1.0] * 6,
                    rss_mb=[100.0, 100.0, 104.0, 104.0, 109.0, 112.0],
                    mismatches=[("b", 3)], unexpected=["a"])
    got.census = {"start": soak.Census(1, 4, 7), "first round": soak.Census(1, 6, 7),
                  "end": soak.Census(2, 8, 9)}
    assert got.rounds == 3 and got.growth() == pytest.approx(0.12)
    fails = got.failures()
    assert len(fails) == 6, fails
    assert "a: unexpected outcome" in fails
    assert "run 3 (b): outcome differs from the first run" in fails
    assert any(f.startswith("RSS grew 12.0 %") for f in fails)
    assert "Python threads 1 -> 2" in fails
    assert any(f.startswith("OS threads 6") for f in fails)
    assert any(f.startswith("open file descriptors 7") for f in fails)
    got.rss_mb[-1], got.census["end"] = 109.0, soak.Census(1, 6, 7)
    got.mismatches, got.unexpected = [], []
    assert got.failures() == []
