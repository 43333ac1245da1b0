"""The soak (testkit.soak; ``python -m bench.soak`` runs it long) in small: a few
evaluations in one process leave no thread or file behind and repeat their first result byte
for byte, which is also a fresh process's."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from testkit import soak
from testkit.paths import REPO

SINGLE_RUN = """
import sys
from pcmapq.evaluation.pipeline import evaluate
sys.stdout.write(evaluate(sys.argv[1], sys.argv[2]).to_json())
"""


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
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    fresh = subprocess.run([sys.executable, "-c", SINGLE_RUN, str(sample.map_path),
                            str(sample.truth_path)], capture_output=True, text=True, check=True,
                           env=env).stdout
    assert fresh == got.first[sample.name]
