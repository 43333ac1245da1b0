"""Soak test (issue 12): many evaluations of varied inputs in one process through the Python
API (``pcmapq.evaluation.pipeline.evaluate``), cycled round-robin. Checks that every run's
outcome equals the first run of its input (the JSON the CLI writes, byte for byte; for an
input that fails by design, the same exception type and message), that the resident memory
after the last round is within 10 % of that after the first, and that threads and open file
descriptors do not grow.

    python -m bench.soak [--runs 200] [--json out.json] [--data DIR]

Prints a markdown summary (the "Soak" section of docs/benchmarks.md); exits 1 when a check
fails. The real-data inputs come from ../shared/data and are left out, saying so, where it is
absent.
"""

from __future__ import annotations

import argparse
import ctypes
import ctypes.util
import gc
import json
import os
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.io.writers import write_ros_map
from pcmapq.settings import AlignmentConfig, Settings, SourceConfig
from pcmapq.testing import synth

from .validation.drift import drifted, save_cloud

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
SAMPLE = ROOT / "data" / "sample"
#: Largest allowed growth of the resident memory from the first round to the last, fraction.
MAX_GROWTH = 0.10
#: A run's outcome: the result's JSON, or "ExceptionType: message".
Outcome = str


@dataclass(frozen=True)
class Input:
    """One soak input: what to evaluate and what it should give (``None``: a result; an
    exception type: that error)."""

    name: str
    map_path: Path
    truth_path: Path
    settings: Settings | None = None
    fails_with: type[Exception] | None = None


def write_plan(segments: np.ndarray, path: Path, resolution: float = 0.05) -> Path:
    """Wall segments (metres) drawn as a ROS map: ``path`` (.png) and its YAML."""
    grid = synth.plan_grid(segments, resolution)
    return write_ros_map(path, synth.render(segments, grid), resolution, grid.origin[:2])


def synthetic_inputs(folder: Path) -> list[Input]:
    """The sample, its truth against itself, synthetic plans seen through known transforms (a
    2D cloud and an image), and two inputs that fail by design: a degenerate map (three
    identical points: EvaluationError) and a missing file (InputError). Files go to
    ``folder``, written once, so every run reads the same paths."""
    one = synth.building_plan(seed=1)
    truth_one = write_plan(one, folder / "plan1.png")
    moved = synth.transform_segments(one, Similarity2D(5.0, -3.0, np.radians(33.0)).inverse())
    cloud = folder / "plan1_cloud.npy"
    np.save(cloud, synth.wall_points(moved, 0.03, noise=0.01))
    two = synth.building_plan(seed=2, width=30.0, height=18.0)
    truth_two = write_plan(two, folder / "plan2.png")
    seen = synth.transform_segments(two, Similarity2D(-2.0, 4.0, np.radians(-120.0)).inverse())
    image = write_plan(seen, folder / "plan2_seen.png")
    degenerate = folder / "three.npy"
    np.save(degenerate, np.full((3, 2), 2.5))
    return [
        Input("sample scan vs truth", SAMPLE / "scan.ply", SAMPLE / "truth.yaml"),
        Input("sample truth vs itself", SAMPLE / "truth.yaml", SAMPLE / "truth.yaml"),
        Input("synthetic cloud, moved 5, -3 m, 33 deg", cloud, truth_one),
        Input("synthetic image, moved -2, 4 m, -120 deg", image, truth_two),
        Input("degenerate map (3 identical points)", degenerate, truth_one,
              fails_with=EvaluationError),
        Input("missing map file", folder / "absent.ply", truth_one, fails_with=InputError),
    ]


def real_inputs(data: Path, folder: Path) -> list[Input]:
    """Small real cases of ../shared/data (a few seconds each): the Freiburg 079 SLAM map vs
    its plan (scale estimated, as docs/validation.md), the FHW CARMEN map from poses drifted
    by 0.5 % (seed 0) vs the log itself, and the Orebro log vs the ACES log (another place:
    refused, EvaluationError)."""
    plans, carmen = data / "floorplans", data / "carmen"
    fhw = carmen / "fhw-corrected.log.gz"
    poses, ranges, angles = read_flaser(fhw)
    drift = save_cloud(endpoints(drifted(poses, 0.005, 0), ranges, angles, DEFAULT_MAX_RANGE),
                       folder / "fhw_drift_0.5.npy")
    return [
        Input("Freiburg 079 map vs its plan", plans / "freiburg_building79.png",
              plans / "Freiburg79_scan.png",
              Settings(alignment=AlignmentConfig(scale=True),
                       truth=SourceConfig(resolution=0.05))),
        Input("CARMEN fhw drifted 0.5 % vs its log", drift, fhw),
        Input("CARMEN orebro vs aces (another place)", carmen / "orebro-corrected.log.gz",
              carmen / "aces-corrected.log.gz", fails_with=EvaluationError),
    ]


def outcome(item: Input) -> Outcome:
    """Evaluate one input: the result's JSON as ``pcmapq eval --json`` writes it, or the error
    of a pipeline failure (InputError, EvaluationError) as "Type: message"."""
    try:
        return evaluate(item.map_path, item.truth_path, item.settings).to_json()
    except (InputError, EvaluationError) as exc:
        return f"{type(exc).__name__}: {exc}"


def rss_mb() -> float:
    """Resident memory of this process now, MB (/proc/self/statm)."""
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 1e6


def release_free_memory() -> None:
    """Collect garbage and hand the C heap's free pages back to the OS (glibc ``malloc_trim``;
    nothing where it is absent), so the RSS read next is the memory still in use, not what the
    allocator keeps for reuse: after these evaluations it kept about 0.1 GB, different
    from run to run, which would hide or fake a growth of 10 %."""
    gc.collect()
    name = ctypes.util.find_library("c")
    if name:
        trim = getattr(ctypes.CDLL(name), "malloc_trim", None)
        if trim is not None:
            trim(0)


@dataclass(frozen=True)
class Census:
    """Python threads (``threading.active_count``), OS threads (/proc/self/task) and open
    file descriptors (/proc/self/fd) of this process at one moment."""

    python_threads: int
    os_threads: int
    fds: int

    @classmethod
    def now(cls) -> Census:
        return cls(threading.active_count(), len(os.listdir("/proc/self/task")),
                   len(os.listdir("/proc/self/fd")))

    @classmethod
    def settled(cls, tries: int = 20, pause: float = 0.05) -> Census:
        """The census once two readings ``pause`` seconds apart agree (at most ``tries``): a
        worker thread that ``evaluate`` joined may still be listed in /proc/self/task for an
        instant after its join returns, while it exits."""
        last = cls.now()
        for _ in range(tries):
            time.sleep(pause)
            now = cls.now()
            if now == last:
                break
            last = now
        return last


@dataclass
class Soak:
    """What a soak measured. ``seconds[i]``: of run i; ``raw_rss_mb[i]``: the RSS right after
    run i, ``rss_mb[i]`` after :func:`release_free_memory` too (the one checked); ``mismatches``:
    the runs whose outcome differs from their input's first (input name, run index)."""

    inputs: list[str]
    runs: int = 0
    seconds: list[float] = field(default_factory=list)
    rss_mb: list[float] = field(default_factory=list)
    raw_rss_mb: list[float] = field(default_factory=list)
    mismatches: list[tuple[str, int]] = field(default_factory=list)
    unexpected: list[str] = field(default_factory=list)
    census: dict[str, Census] = field(default_factory=dict)
    first: dict[str, Outcome] = field(default_factory=dict)

    @property
    def rounds(self) -> int:
        """Full rounds of the inputs run."""
        return self.runs // len(self.inputs)

    def rss_first_round(self) -> float:
        """RSS after the first full round, MB."""
        return self.rss_mb[len(self.inputs) - 1]

    def rss_last_round(self) -> float:
        """RSS after the last full round, MB."""
        return self.rss_mb[self.rounds * len(self.inputs) - 1]

    def growth(self) -> float:
        """RSS growth from the first full round to the last, fraction."""
        return self.rss_last_round() / self.rss_first_round() - 1.0

    def failures(self) -> list[str]:
        """Every check that fails, one line each (none: the soak passed)."""
        out = [f"{name}: {why}" for name, why in
               ((n, "unexpected outcome") for n in self.unexpected)]
        out += [f"run {i} ({name}): outcome differs from the first run" for name, i in
                self.mismatches]
        if self.rounds < 2:
            out.append(f"only {self.rounds} full round(s) of {len(self.inputs)} inputs: "
                       "no growth measured")
        elif self.growth() > MAX_GROWTH:
            out.append(f"RSS grew {100 * self.growth():.1f} % (first round "
                       f"{self.rss_first_round():.0f} MB, last {self.rss_last_round():.0f} MB)")
        start, warm, end = (self.census[k] for k in ("start", "first round", "end"))
        if end.python_threads > start.python_threads:
            out.append(f"Python threads {start.python_threads} -> {end.python_threads}")
        if end.os_threads > warm.os_threads:
            out.append(f"OS threads {warm.os_threads} after the first round -> "
                       f"{end.os_threads}")
        if end.fds > warm.fds:
            out.append(f"open file descriptors {warm.fds} after the first round -> {end.fds}")
        return out

    def summary(self) -> dict:
        """The figures as plain JSON types."""
        return {"runs": self.runs, "inputs": self.inputs, "rounds": self.rounds,
                "seconds": sum(self.seconds), "seconds_per_run": self.seconds,
                "rss_mb": self.rss_mb, "raw_rss_mb": self.raw_rss_mb,
                "rss_first_round_mb": self.rss_first_round() if self.rounds else None,
                "rss_last_round_mb": self.rss_last_round() if self.rounds else None,
                "growth": self.growth() if self.rounds else None,
                "census": {k: asdict(v) for k, v in self.census.items()},
                "mismatches": self.mismatches, "unexpected": self.unexpected,
                "failures": self.failures()}


def expected(item: Input, got: Outcome) -> bool:
    """Whether a first outcome is the kind its input should give."""
    if item.fails_with is None:
        return got.startswith("{")
    return got.startswith(f"{item.fails_with.__name__}: ")


def soak(items: list[Input], runs: int,
         progress: Callable[[int, Input, float], None] = lambda i, item, s: None) -> Soak:
    """Evaluate ``items`` round-robin, ``runs`` evaluations in all, in this process."""
    got = Soak([item.name for item in items])
    got.census["start"] = Census.settled()
    for i in range(runs):
        item = items[i % len(items)]
        start = time.perf_counter()
        now = outcome(item)
        got.seconds.append(time.perf_counter() - start)
        got.raw_rss_mb.append(rss_mb())
        release_free_memory()
        got.rss_mb.append(rss_mb())
        got.runs += 1
        if item.name not in got.first:
            got.first[item.name] = now
            if not expected(item, now):
                got.unexpected.append(item.name)
        elif now != got.first[item.name]:
            got.mismatches.append((item.name, i))
        if i == len(items) - 1:
            got.census["first round"] = Census.settled()
        progress(i, item, got.seconds[-1])
    got.census["end"] = Census.settled()
    got.census.setdefault("first round", got.census["end"])
    return got


def markdown(got: Soak, data_note: str = "") -> str:
    """The soak's figures as the markdown of docs/benchmarks.md."""
    per = {name: [s for i, s in enumerate(got.seconds) if i % len(got.inputs) == k]
           for k, name in enumerate(got.inputs)}
    lines = ["| input | runs | s per run (median) | outcome |", "|---|---:|---:|---|"]
    for name, secs in per.items():
        first = got.first[name]
        kind = "result" if first.startswith("{") else first.split(":")[0]
        lines.append(f"| {name} | {len(secs)} | {float(np.median(secs)):.2f} | {kind} |")
    c = got.census
    fails = got.failures()
    lines += ["", f"{got.runs} evaluations, {len(got.inputs)} inputs round-robin "
              f"({got.rounds} full rounds), {sum(got.seconds):.0f} s. RSS in use (after "
              f"`gc.collect()` and `malloc_trim(0)`) after the first round "
              f"{got.rss_first_round():.0f} MB, after the last {got.rss_last_round():.0f} MB: "
              f"growth {100 * got.growth():+.1f} % (limit {100 * MAX_GROWTH:.0f} %); over all "
              f"runs {min(got.rss_mb):.0f}-{max(got.rss_mb):.0f} MB. RSS as the allocator left "
              f"it (before the trim): {min(got.raw_rss_mb):.0f}-{max(got.raw_rss_mb):.0f} MB, "
              f"{got.raw_rss_mb[len(got.inputs) - 1]:.0f} MB after the first round, "
              f"{got.raw_rss_mb[got.rounds * len(got.inputs) - 1]:.0f} MB after the last. "
              "Python threads "
              f"{c['start'].python_threads} / {c['first round'].python_threads} / "
              f"{c['end'].python_threads}, OS threads {c['start'].os_threads} / "
              f"{c['first round'].os_threads} / {c['end'].os_threads}, open file descriptors "
              f"{c['start'].fds} / {c['first round'].fds} / {c['end'].fds} (before the first "
              "run / after the first round / at the end). "
              + ("Every outcome equals its input's first." if not got.mismatches else
                 f"{len(got.mismatches)} outcomes differ from their input's first.")
              + (" " + data_note if data_note else ""),
              "", "Passed." if not fails else "Failed: " + "; ".join(fails) + "."]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.soak",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=200, help="evaluations (default: 200)")
    parser.add_argument("--json", type=Path, help="write the figures (every run's) here")
    parser.add_argument("--data", type=Path, default=DATA,
                        help="the shared data folder (default: %(default)s)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="pcmapq_soak_") as tmp:
        items = synthetic_inputs(Path(tmp))
        note = ""
        if args.data.is_dir():
            items += real_inputs(args.data, Path(tmp))
        else:
            note = f"{args.data} absent: real-data inputs left out."
            print(note, file=sys.stderr)

        def progress(i: int, item: Input, seconds: float) -> None:
            print(f"{i + 1}/{args.runs} {item.name}: {seconds:.2f} s, {rss_mb():.0f} MB "
                  f"in use",
                  file=sys.stderr, flush=True)

        got = soak(items, args.runs, progress)
    print(markdown(got, note))
    if args.json:
        args.json.write_text(json.dumps(got.summary(), indent=1) + "\n")
    return 1 if got.failures() else 0


if __name__ == "__main__":
    sys.exit(main())
