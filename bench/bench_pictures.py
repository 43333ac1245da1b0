"""Time and memory of the pictures (`--plot`, `--report`) on a large truth: the Gazebo pair
(an 8904 x 6936 truth, 62 M cells of 1.89 mm), evaluated with and without them.

    python bench/bench_pictures.py [--repeat 1]   prints a markdown table

Each run does what `pcmapq eval gazebo/SLAM_Gen_Map.png gazebo/Ground_Truth.png
--truth-resolution 1/529 --scale auto [--plot P] [--report R]` does (as docs/validation.md runs
this pair): ``evaluate``, then ``png_bytes(vectorial_figure(result))`` for the plot and
``report_html(result)`` for the report, in a fresh process, so its peak RSS is its own. The
pictures are timed apart from the evaluation (on a shared machine the evaluation's time varies
by more than the pictures cost), and their own peak is read apart too: the kernel's peak (VmHWM)
is reset between the two (``/proc/self/clear_refs``). The fastest of ``--repeat`` runs is kept.
Skips, saying so, when ../shared/data/gazebo is absent.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

GAZEBO = Path(__file__).resolve().parents[2] / "shared" / "data" / "gazebo"
MAP, TRUTH = GAZEBO / "SLAM_Gen_Map.png", GAZEBO / "Ground_Truth.png"
#: The Gazebo truth's cell, metres (529 px per metre, ../shared/README.md).
RESOLUTION = 1.0 / 529.0

CHILD = r"""
import json, resource, sys, time
from pcmapq.settings import AlignmentConfig, Settings, SourceConfig
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.html import report_html
from pcmapq.report.plot import png_bytes, vectorial_figure

def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) / 1024 for line in f if line.startswith(key))

def cpu():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime

case, map_path, truth_path, res = sys.argv[1:5]
start = time.perf_counter()
settings = Settings(truth=SourceConfig(resolution=float(res)),
                    alignment=AlignmentConfig(scale=True))
result = evaluate(map_path, truth_path, settings)
evaluated, cpu0 = time.perf_counter(), cpu()
evaluation_peak, resident = status("VmHWM:"), status("VmRSS:")
with open("/proc/self/clear_refs", "w") as f:  # the peak restarts from the resident memory
    f.write("5")
if case in ("plot", "both"):
    png_bytes(vectorial_figure(result))
if case in ("report", "both"):
    report_html(result)
pictures_peak = status("VmHWM:")
print(json.dumps({"evaluate_s": evaluated - start, "seconds": time.perf_counter() - evaluated,
                  "cpu_s": cpu() - cpu0, "peak_mb": max(evaluation_peak, pictures_peak),
                  "own_mb": pictures_peak - resident, "resident_mb": resident}))
"""

CASES = {"none": "no pictures", "plot": "`--plot`", "report": "`--report`",
         "both": "`--plot --report`"}


def child(case: str) -> dict:
    """One case in a fresh process: what it printed last (JSON)."""
    proc = subprocess.run([sys.executable, "-c", CHILD, case, str(MAP), str(TRUTH),
                           repr(RESOLUTION)], capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    if not GAZEBO.is_dir():
        print(f"skipped: {GAZEBO} is absent (the Gazebo pair of ../shared/data)")
        return
    rows = {case: min((child(case) for _ in range(args.repeat)), key=lambda r: r["seconds"])
            for case in CASES}
    print(f"Gazebo pair, fastest of {args.repeat} (by the pictures' time); own peak: the "
          "pictures' rise over the memory the evaluation left resident")
    print("| run | evaluation s | pictures s | pictures CPU s | peak RSS MB | own peak MB |")
    print("|---|---:|---:|---:|---:|---:|")
    for case, r in rows.items():
        print(f"| {CASES[case]} | {r['evaluate_s']:.1f} | {r['seconds']:.1f} | {r['cpu_s']:.1f} | "
              f"{r['peak_mb']:.0f} | {r['own_mb']:.0f} (over {r['resident_mb']:.0f}) |")


if __name__ == "__main__":
    main()
