"""Where one ``pcmapq eval`` holds its memory: its resident memory sampled over time beside the
stages running then, on every thread (tracemalloc sees NumPy's arrays but not Open3D's,
small_gicp's or the files mapped into memory; the resident set sees them all).

    python -m bench.memory_timeline MAP TRUTH [--every 0.05] [--limit 12] [--without-3d]

The evaluation runs in this process (``pcmapq.evaluation.pipeline.evaluate``, default
settings); a thread reads the resident set (``/proc/self/statm``) every ``--every`` seconds.
Each stage of :data:`STAGES` is timed wherever it runs. Printed: the run's wall seconds and
peak, then one row a stage: its thread, start and end (seconds into the run), the resident
memory when it started and the most while it ran (GB; stages overlap on other threads, so a
row's most is the whole process's, not the stage's own). ``--limit GB``: stop the run (exit
3) when the resident set passes it, the rows so far printed (a run the machine cannot hold
ends before the kernel's kill). ``--without-3d``: without the 3D figures of two clouds (as
:mod:`bench.bench_large3d`'s other side). Linux only.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import os
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

#: (module, function or Class.method) of each stage timed.
STAGES = [
    ("pcmapq.evaluation.inputs", "load_pair"),
    ("pcmapq.evaluation.truth", "prepare_truth"),
    ("pcmapq.raster.slice", "wall_band"),
    ("pcmapq.align.rigid3d", "align_3d"),
    ("pcmapq.align.features3d", "global_registration"),
    ("pcmapq.align.refine3d", "refine"),
    ("pcmapq.align.rigid3d", "apply"),
    ("pcmapq.evaluation.placing", "align_plan"),
    ("pcmapq.evaluation.placing", "map_raster"),
    ("pcmapq.evaluation.scoring", "score"),
    ("pcmapq.metrics.distances", "distances_3d"),
    ("pcmapq.align.regions3d", "regions_3d"),
    ("pcmapq.metrics.map_gaussians", "map_gaussians"),
    ("pcmapq.evaluation.scoring", "structures_3d"),
    ("pcmapq.evaluation.truth", "find_planes"),
    ("pcmapq.match.structures", "find_planes"),
    ("pcmapq.evaluation.noref_figures", "input_figures"),
    ("pcmapq.features.registry", "SideBySide.features"),
]
PAGE = os.sysconf("SC_PAGE_SIZE")


def resident() -> int:
    """This process's resident set, bytes."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * PAGE


@dataclass
class Timeline:
    """Samples (seconds, bytes) and stages (name, thread, start, end; end None while it
    runs), seconds from ``start``."""

    start: float = field(default_factory=time.perf_counter)
    samples: list[tuple[float, int]] = field(default_factory=list)
    stages: list[list] = field(default_factory=list)

    def now(self) -> float:
        return time.perf_counter() - self.start

    def timed(self, fn: Callable, name: str) -> Callable:
        """``fn`` recording its start and end as stage ``name``."""
        @functools.wraps(fn)
        def inner(*args, **kwargs):
            row = [name, threading.current_thread().name, self.now(), None]
            self.stages.append(row)
            try:
                return fn(*args, **kwargs)
            finally:
                row[3] = self.now()
        return inner

    def rows(self) -> list[str]:
        """The stages' table, by start."""
        out = ["| stage | thread | start s | end s | GB at start | most GB while it ran |",
               "|---|---|---:|---:|---:|---:|"]
        for name, thread, t0, t1 in sorted(self.stages, key=lambda r: r[2]):
            end = self.now() if t1 is None else t1
            before = [b for t, b in self.samples if t <= t0] or [0]
            during = [b for t, b in self.samples if t0 <= t <= end] or before[-1:]
            out.append(f"| {name} | {thread} | {t0:.1f} | "
                       f"{'running' if t1 is None else f'{t1:.1f}'} | {before[-1] / 1e9:.2f} | "
                       f"{max(during) / 1e9:.2f} |")
        return out


def instrument(wrap: Callable[[Callable, str, str], Callable],
               stages: list[tuple[str, str]] = STAGES) -> None:
    """Replace every stage of ``stages`` (module, function or Class.method) by ``wrap(fn,
    module, name)`` where it is defined and wherever pcmapq imported it."""
    wrapped = {}
    for module, name in stages:
        owner = importlib.import_module(module)
        if "." in name:  # a method: wrapped on its class
            owner = getattr(owner, name.split(".")[0])
        attr = name.split(".")[-1]
        fn = getattr(owner, attr)
        if owner is not sys.modules.get(module):
            setattr(owner, attr, wrap(fn, module, name))
            continue
        wrapped.setdefault(id(fn), (fn, wrap(fn, module, name)))
    for module in list(sys.modules.values()):
        if getattr(module, "__name__", "").startswith("pcmapq"):
            for attr, value in list(vars(module).items()):
                if id(value) in wrapped and value is wrapped[id(value)][0]:
                    setattr(module, attr, wrapped[id(value)][1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("map")
    parser.add_argument("truth")
    parser.add_argument("--every", type=float, default=0.05, help="seconds between samples")
    parser.add_argument("--limit", type=float, default=None, help="GB: stop the run above it")
    parser.add_argument("--without-3d", action="store_true")
    args = parser.parse_args()
    import pcmapq.evaluation.scoring as scoring
    from pcmapq.evaluation.pipeline import evaluate
    from pcmapq.settings import Settings

    settings = Settings()
    if args.without_3d:
        scoring.in_one_frame_3d = lambda *a: False
        scoring.regions_3d = lambda *a, **k: None
        settings = replace(settings, structures=replace(settings.structures, enabled=False))
    line = Timeline()
    instrument(lambda fn, _, name: line.timed(fn, name))
    done = threading.Event()

    def sample() -> None:
        while not done.is_set():
            line.samples.append((line.now(), resident()))
            if args.limit is not None and line.samples[-1][1] > args.limit * 1e9:
                print(f"stopped: {line.samples[-1][1] / 1e9:.2f} GB resident at "
                      f"{line.now():.1f} s, over --limit", *line.rows(), sep="\n", flush=True)
                os._exit(3)
            time.sleep(args.every)

    threading.Thread(target=sample, daemon=True).start()
    evaluate(args.map, args.truth, settings)
    done.set()
    peak = max(line.samples, key=lambda s: s[1])
    print(f"wall {line.now():.1f} s; peak {peak[1] / 1e9:.2f} GB at {peak[0]:.1f} s",
          *line.rows(), sep="\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
