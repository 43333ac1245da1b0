"""What the sections share: the data folder, cases and the record of their figures, timed runs
of the pipeline, and how figures are written."""

from __future__ import annotations

import contextlib
import resource
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Generic, Protocol, TypeVar

import numpy as np

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import PointMap
from pcmapq.io.map_yaml import MapMeta
from pcmapq.io.occupancy import read_levels
from pcmapq.report.text import score
from pcmapq.results.result import Result
from pcmapq.settings import Settings

from .reference import summary

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT.parent / "shared" / "data"

#: The figures of every case measured so far, by case name (what its reference stores).
Record = dict[str, dict]


class Measured(Protocol):
    """What a case measured: it says which of its figures the case's reference keeps."""

    def summary(self) -> dict:
        """The figures kept in the case's reference."""
        ...


M = TypeVar("M", bound=Measured)


@dataclass(frozen=True)
class Case(Generic[M]):
    """One measured case of docs/validation.md: the name of its reference
    (``tests/reference/validation/<name>.json``) and how to measure it."""

    name: str
    measure: Callable[[], M]

    def run(self, record: Record) -> M:
        """Measure the case and keep its figures in ``record``."""
        measured = self.measure()
        record[self.name] = measured.summary()
        return measured


@dataclass(frozen=True)
class Section:
    """A section's markdown and the files it shows (paths relative to docs/, contents)."""

    text: str
    files: dict[str, bytes] = field(default_factory=dict)


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


def with_yaml(image: Path, folder: Path, resolution: float, **thresholds: float) -> Path:
    """A copy of ``image`` in ``folder`` with a map_server YAML beside it (origin 0, the given
    thresholds over ROS's defaults); returns the YAML's path."""
    copy = folder / image.name
    shutil.copyfile(image, copy)
    meta = {"occupied_thresh": 0.65, "free_thresh": 0.196, **thresholds}
    yaml_path = copy.with_suffix(".yaml")
    yaml_path.write_text(f"image: {copy.name}\nresolution: {resolution}\norigin: [0, 0, 0]\n"
                         f"negate: 0\noccupied_thresh: {meta['occupied_thresh']}\n"
                         f"free_thresh: {meta['free_thresh']}\n")
    return yaml_path


def commonest_greys(image: Path, count: int = 3) -> list[int]:
    """The ``count`` most frequent grey values of an image as pcmapq's loader reads it (0..255),
    darkest first."""
    levels, channels, scale, _ = read_levels(image)
    grey = levels / channels * scale
    values, counts = np.unique(np.rint(grey), return_counts=True)
    return sorted(int(v) for v in values[np.argsort(-counts, kind="stable")[:count]])


def occupancy(grey: int) -> str:
    """'p = 0.50' for a grey value, map_server's occupancy probability (not negated)."""
    return f"p = {(255 - grey) / 255:.2f}"


#: map_server's default thresholds (a map without YAML or options).
ROS = MapMeta(resolution=None)


def cm(value: float | None) -> str:
    """Metres as centimetres, two decimals ('-' for None)."""
    return "-" if value is None else f"{100 * value:.2f}"


def q_p(result: Result, name: str) -> str:
    """'q / p' of one detector of a result."""
    m = result.detectors[name].matching
    return f"{score(m.quality, 2)} / {score(m.precision, 2)}"


def qualities(result: Result) -> str:
    """'harris q / p, hough q / p, sift q / p' of a result."""
    return ", ".join(f"{name} {q_p(result, name)}" for name in result.detectors)


def f_at(result: Result, tau: float, three_d: bool = False) -> float | None:
    """The F-score at distance threshold ``tau`` metres (of the 3D distances if asked)."""
    dist = result.distances_3d if three_d else result.distances
    return next((f.f for f in dist.fscores if abs(f.tau_m - tau) < 1e-9), None)


def yaw_error(yaw_deg: float, expected_deg: float) -> float:
    """Smallest absolute difference of two angles, degrees."""
    return abs((yaw_deg - expected_deg + 180.0) % 360.0 - 180.0)


def span(values: list[float], digits: int = 2) -> str:
    """'lo-hi' of some figures ('x' when they are all one)."""
    lo, hi = f"{min(values):.{digits}f}", f"{max(values):.{digits}f}"
    return lo if lo == hi else f"{lo}-{hi}"


def row(cells: list[str]) -> str:
    """One markdown table row."""
    return "| " + " | ".join(cells) + " |"


def header(cells: list[str]) -> str:
    """A markdown table's header and rule."""
    return row(cells) + "\n|" + " --- |" * len(cells)
