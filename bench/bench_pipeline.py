"""Time and memory of `pcmapq eval` end to end, per stage, on the sample and on larger plans.

    python -m bench.bench_pipeline        prints a markdown table (copied into docs/benchmarks.md)

Each case runs in a fresh process so its peak memory (max RSS) is its own.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

from pcmapq.report.text import score

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, resource, sys, time
from pathlib import Path
import numpy as np
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
sys.path.insert(0, sys.argv[1])
from testkit import synth
from testkit.files import in_map_frame, write_cloud_map, write_image_map

case, out = sys.argv[2], Path(sys.argv[3])
if case == "sample":
    root = Path(sys.argv[1])
    map_path, truth_path = root / "data/sample/scan.ply", root / "data/sample/truth.png"
else:
    sizes = {"plan 24x16 m": (24, 16), "plan 60x40 m": (60, 40), "plan 120x80 m": (120, 80)}
    width, height = sizes[case]
    plan = synth.building_plan(seed=1, width=width, height=height)
    truth_path = write_image_map(plan, out / "truth.png")
    tf = Similarity2D(5.0, -3.0, np.radians(33.0))
    cloud = synth.wall_points(in_map_frame(plan, tf), 0.03, noise=0.01)
    map_path = write_cloud_map(cloud, out / "map.npy")
times, last = {}, [time.perf_counter(), "start"]
def progress(step):
    now = time.perf_counter()
    times[last[1]] = times.get(last[1], 0.0) + now - last[0]
    last[:] = [now, step.split()[0]]
t0 = time.perf_counter()
result = evaluate(map_path, truth_path, progress=progress)
progress("end")
times["total"] = time.perf_counter() - t0
times.pop("start", None)
print(json.dumps({"case": case, "grid": list(result.grid.shape), "times": times,
                  "quality": {n: d.matching.quality for n, d in result.detectors.items()},
                  "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def main() -> None:
    rows = []
    for case in ("sample", "plan 24x16 m", "plan 60x40 m", "plan 120x80 m"):
        with tempfile.TemporaryDirectory() as tmp:
            proc = subprocess.run([sys.executable, "-c", CHILD, str(ROOT), case, tmp],
                                  capture_output=True, text=True, check=True)
        rows.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    steps = ["loading", "aligning", "rasterising", "drawing", "total"]
    # "drawing the walls' centre lines and detecting features"; "aligning" holds the regions'
    names = {"drawing": "wall centre lines and features"}
    detectors = "/".join(rows[0]["quality"])
    print("| case | grid (rows x cols) | " + " | ".join(f"{names.get(s, s)} s" for s in steps)
          + f" | peak RSS MB | quality {detectors} |")
    print("|---" * (len(steps) + 4) + "|")
    for r in rows:
        q = "/".join(score(v, 2) for v in r["quality"].values())
        t = " | ".join(f"{r['times'].get(s, 0.0):.2f}" for s in steps)
        print(f"| {r['case']} | {r['grid'][0]} x {r['grid'][1]} | {t} | {r['rss_mb']:.0f} | {q} |")


if __name__ == "__main__":
    main()
