"""A soak in one process: many evaluations of varied inputs through the Python API
(``pcmapq.evaluation.pipeline.evaluate``), cycled round-robin, checking that every run's
outcome equals the first run of its input (the JSON the CLI writes, byte for byte; for an input
that fails by design, the same exception type and message), that the resident memory after the
last round is within 10 % of that after the first, and that threads and open file descriptors
do not grow. ``python -m bench.soak`` runs it long, with real data too; the tests run it in
small."""

from __future__ import annotations

import ctypes
import ctypes.util
import gc
import os
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io.writers import write_ros_map
from pcmapq.settings import Settings

from . import synth
from .paths import SAMPLE

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
