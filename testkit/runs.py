"""Timed evaluations and the figures read off their results, for the validation's cases
(``bench/validation``), the drift ladder and the tests that check them."""

from __future__ import annotations

import contextlib
import resource
import time
from dataclasses import dataclass
from pathlib import Path

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import PointMap
from pcmapq.results.result import Result
from pcmapq.settings import Settings

from .reference import summary


@dataclass(frozen=True)
class Run:
    """One timed evaluation: the result, seconds per progress step, in all, and the peak
    resident memory (GB) of the process during it."""

    result: Result
    steps: dict[str, float]
    seconds: float
    peak_gb: float

    def summary(self) -> dict:
        return summary(self.result.to_dict())


def reset_peak() -> None:
    """Measure the peak resident memory afresh from now (Linux: /proc/self/clear_refs)."""
    with contextlib.suppress(OSError):
        Path("/proc/self/clear_refs").write_text("5")


def peak_rss_gb() -> float:
    """Peak resident memory of this process since :func:`reset_peak`, GB (Linux's VmHWM; the
    peak of the whole process where /proc is absent)."""
    with contextlib.suppress(OSError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1e6
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6


def timed_evaluate(map_path: Path | PointMap, truth_path: Path,
                   settings: Settings | None = None) -> Run:
    """``evaluate`` with the time of each step, measured by its progress callback."""
    marks: list[tuple[str, float]] = []
    reset_peak()
    start = time.perf_counter()
    result = evaluate(map_path, truth_path, settings,
                      lambda step: marks.append((step, time.perf_counter())))
    end = time.perf_counter()
    marks.append(("", end))
    steps = {}
    for i, ((step, t0), (_, t1)) in enumerate(zip(marks, marks[1:], strict=False)):
        steps[step + (" + distances" if i == len(marks) - 2 else "")] = t1 - t0
    return Run(result, steps, end - start, peak_rss_gb())


def f_at(result: Result, tau: float, three_d: bool = False) -> float | None:
    """The F-score at distance threshold ``tau`` metres (of the 3D distances if asked)."""
    dist = result.distances_3d if three_d else result.distances
    return next((f.f for f in dist.fscores if abs(f.tau_m - tau) < 1e-9), None)


def yaw_error(yaw_deg: float, expected_deg: float) -> float:
    """Smallest absolute difference of two angles, degrees."""
    return abs((yaw_deg - expected_deg + 180.0) % 360.0 - 180.0)
