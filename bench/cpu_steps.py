"""Where one ``pcmapq eval``'s CPU goes: each step's CPU seconds, whichever thread runs it; a
markdown table.

    python -m bench.cpu_steps MAP TRUTH

The evaluation runs in this process (``pcmapq.evaluation.pipeline.evaluate``, default
settings) with the libraries' own thread pools held to one thread (OpenMP, OpenCV, Open3D), so
that a step's work is all on the thread that calls it: its CPU is that thread's CPU time
(``time.thread_time``) over the call, less the steps it calls itself. The pipeline's own
threads still run side by side; a step's seconds are its own however they overlap. The rest of
the process's CPU (``resource.getrusage``) is what no step listed holds: importing the
libraries, the threads' start, the command's own glue. The wall time of this run is not the
command's: the libraries' pools run on one thread here.
"""

from __future__ import annotations

import argparse
import functools
import os
import resource
import sys
import threading
import time
from collections import defaultdict
from collections.abc import Callable

from bench.memory_timeline import instrument

#: (module, function, label) of each step measured; a detector's label names the detector.
STEPS = [
    ("pcmapq.evaluation.inputs", "load_pair", "loading both clouds"),
    ("pcmapq.evaluation.truth", "prepare_truth", "the truth's raster"),
    ("pcmapq.align.rigid3d", "align_3d", "the 3D registration: the clouds' voxels"),
    ("pcmapq.align.features3d", "global_registration", "the 3D registration: global search"),
    ("pcmapq.align.refine3d", "refine", "the 3D registration: ICP"),
    ("pcmapq.align.rigid3d", "score", "the 3D registration: its fitness"),
    ("pcmapq.raster.slice", "wall_band", "the wall bands of the clouds"),
    ("pcmapq.evaluation.placing", "align_plan", "the plan's alignment"),
    ("pcmapq.evaluation.placing", "map_raster", "the map's raster"),
    ("pcmapq.features.walls", "_band", "the detectors' wall images, both sides"),
    ("pcmapq.features.registry", "detect_in", "detector {0}, both sides"),
    ("pcmapq.features.planes3d", "find_planes", "the 3D structures: planes, both clouds"),
    ("pcmapq.match.structures", "compare_structures", "the 3D structures: lines, matching"),
    ("pcmapq.align.regions", "regions", "the 2D consistency map"),
    ("pcmapq.align.regions3d", "regions_3d", "the 3D consistency map"),
    ("pcmapq.metrics.distances", "distances_3d", "the 3D distances"),
    ("pcmapq.metrics.map_gaussians", "map_gaussians", "AWD and SCS"),
    ("pcmapq.evaluation.noref_figures", "input_figures", "the no-reference figures, both clouds"),
    ("pcmapq.evaluation.scoring", "score", "scoring: features matched, distances, the result"),
]


class Ledger:
    """CPU seconds by label; a per-thread stack of the steps running, so that a step's seconds
    leave out the steps it calls."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self.local = threading.local()
        self.lock = threading.Lock()

    def timed(self, fn: Callable, name: str, label: str) -> Callable:
        @functools.wraps(fn)
        def inner(*args, **kwargs):
            stack = self.local.__dict__.setdefault("stack", [])
            stack.append(0.0)
            start = time.thread_time()
            try:
                return fn(*args, **kwargs)
            finally:
                spent = time.thread_time() - start
                inner_steps = stack.pop()
                own = spent - inner_steps
                if stack:
                    stack[-1] += spent
                with self.lock:
                    self.seconds[label.format(*args[:1])] += own
        return inner


def one_thread_pools() -> None:
    """The libraries' own thread pools held to one thread, in this process and its children."""
    os.environ["OMP_NUM_THREADS"] = "1"
    import cv2
    import open3d

    cv2.setNumThreads(1)
    open3d.utility.set_max_threads(1)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("map")
    parser.add_argument("truth")
    args = parser.parse_args()
    one_thread_pools()
    import pcmapq.align.refine3d as refine3d
    import pcmapq.features.planes3d as planes3d
    import pcmapq.features.walls as walls
    from pcmapq.evaluation.pipeline import evaluate

    refine3d.PREPARE_THREADS = planes3d.THREADS = 1  # small_gicp's searches, on the caller
    walls._DRAWING = threading.BoundedSemaphore(1)
    ledger = Ledger()
    labels = {(module, name): label for module, name, label in STEPS}
    instrument(lambda fn, module, name: ledger.timed(fn, name, labels[module, name]),
               list(labels))
    start = time.perf_counter()
    evaluate(args.map, args.truth)
    wall = time.perf_counter() - start
    usage = [resource.getrusage(who) for who in (resource.RUSAGE_SELF,
                                                 resource.RUSAGE_CHILDREN)]
    total = sum(u.ru_utime + u.ru_stime for u in usage)
    steps = sorted(ledger.seconds.items(), key=lambda kv: -kv[1])
    rest = total - sum(s for _, s in steps)
    print(f"{total:.1f} s of CPU in all ({wall:.1f} s of wall here)\n")
    print("| step | CPU s | share |\n|---|---:|---:|")
    rest_label = "the rest: importing the libraries, the command's own glue"
    for label, seconds in [*steps, (rest_label, rest)]:
        print(f"| {label} | {seconds:.2f} | {100 * seconds / total:.0f} % |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
