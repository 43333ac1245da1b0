"""Where one ``pcmapq eval`` spends its time: the main thread's stages, profiled; a markdown table.

    python -m bench.bench_profile MAP TRUTH [--top 12]

The pipeline's stages (loading, the 3D registration's global search and ICP, the plan's
alignment, rasterising, the map's features, the consistency map, the 3D distances, waiting for
the background threads) as cumulative seconds of the main thread under cProfile, beside the
whole run. Work done on other threads (the truth's features, the no-reference figures, the
consistency map and 3D distances while the map's features are found) shows as the time the main
thread waits for it. Below the table, one more run without the profiler: its wall time and the
CPU time of all its threads (user and system), which bounds the wall time on this many cores
however well the work overlaps.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import resource
import time
from pathlib import Path

from pcmapq.evaluation.pipeline import evaluate

#: (label, module path suffix, function name) of each stage.
STAGES = [
    ("loading both inputs", "evaluation/inputs.py", "load_pair"),
    ("the truth prepared (raster, distance field)", "evaluation/truth.py", "prepare_truth"),
    ("placing the map", "evaluation/placing.py", "place"),
    ("  3D registration", "align/rigid3d.py", "align_3d"),
    ("    global search (FPFH + RANSAC)", "align/features3d.py", "global_registration"),
    ("    ICP", "align/refine3d.py", "refine"),
    ("    fitness", "align/rigid3d.py", "score"),
    ("  the wall band and levelling", "raster/slice.py", "wall_band"),
    ("  the plan's alignment", "evaluation/placing.py", "align_plan"),
    ("  rasterising", "evaluation/placing.py", "map_raster"),
    ("scoring", "evaluation/scoring.py", "score"),
    ("  the map's features", "features/registry.py", "features"),
    ("  waiting for a thread", "threading.py", "wait"),
]


def profile(map_path: Path, truth: Path) -> tuple[float, dict[str, float]]:
    """Seconds of the whole evaluation and of each stage."""
    profiler = cProfile.Profile()
    start = time.perf_counter()
    profiler.runcall(evaluate, map_path, truth)
    total = time.perf_counter() - start
    stats = pstats.Stats(profiler).stats  # type: ignore[attr-defined]
    found = {}
    for label, where, name in STAGES:
        found[label] = sum(v[3] for (path, _, func), v in stats.items()
                           if func == name and path.endswith(where))
    return total, found


def cpu(map_path: Path, truth: Path) -> tuple[float, float, float]:
    """Wall, user and system seconds of one evaluation, all its threads."""
    before, start = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    evaluate(map_path, truth)
    wall, after = time.perf_counter() - start, resource.getrusage(resource.RUSAGE_SELF)
    return wall, after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("map", type=Path)
    parser.add_argument("truth", type=Path)
    args = parser.parse_args()
    evaluate(args.map, args.truth)  # warm: compiled code, caches
    total, found = profile(args.map, args.truth)
    print("| stage (main thread) | seconds | share |")
    print("|---|---:|---:|")
    for label, seconds in found.items():
        print(f"| {label} | {seconds:.2f} | {100 * seconds / total:.0f} % |")
    print(f"| **the evaluation** | **{total:.2f}** | 100 % |")
    wall, user, system = cpu(args.map, args.truth)
    cores = len(os.sched_getaffinity(0))
    print(f"\nWithout the profiler: {wall:.2f} s wall; CPU {user:.2f} s user + {system:.2f} s "
          f"system, so at least {(user + system) / cores:.2f} s on {cores} cores.")


if __name__ == "__main__":
    main()
