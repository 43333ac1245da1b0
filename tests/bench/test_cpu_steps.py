"""``python -m bench.cpu_steps MAP TRUTH`` (docs/benchmarks.md's table of where pcmapq's CPU
goes) on the sample: every step's seconds its own, so that the steps and the rest add up to the
process's CPU, none negative. Tests reach bench/ only through its command lines, in a
subprocess."""

from __future__ import annotations

import re
import subprocess
import sys

from testkit.paths import REPO, SAMPLE


def test_the_steps_and_the_rest_add_up_to_the_processs_cpu() -> None:
    got = subprocess.run([sys.executable, "-m", "bench.cpu_steps", str(SAMPLE / "scan.ply"),
                          str(SAMPLE / "truth.png")], cwd=REPO, capture_output=True, text=True,
                         timeout=300)
    assert got.returncode == 0, got.stderr
    total = float(re.match(r"([\d.]+) s of CPU in all", got.stdout)[1])
    rows = dict(re.findall(r"^\| (.+?) \| (-?[\d.]+) \| -?\d+ % \|$", got.stdout, re.M))
    # the sample's map is a cloud scored against an image: its wall band, the wall images
    # and the four detectors of both sides
    for step in ("the wall bands of the clouds", "the detectors' wall images, both sides",
                 "detector harris, both sides", "detector sift, both sides"):
        assert float(rows[step]) > 0, got.stdout
    assert all(float(s) >= 0 for s in rows.values()), got.stdout
    assert abs(sum(float(s) for s in rows.values()) - total) <= 0.05 * len(rows), got.stdout
