"""What the sections share: the data folder, cases and the record of their figures, and how
figures are written (timed runs of the pipeline: :mod:`testkit.runs`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Generic, Protocol, TypeVar

import numpy as np

from pcmapq.evaluation.same_place import RECALL_NONE, STANDS_OUT
from pcmapq.io.map_yaml import MapMeta
from pcmapq.io.occupancy import read_levels
from pcmapq.report.text import score
from pcmapq.results.result import Result

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


def stand_out_rule() -> str:
    """The verdict's stand-out rule in one sentence, beside the most distinct other place a
    section measured (its margin)."""
    return (f"A pose of distinctiveness {STANDS_OUT} or more, with a truth recall above "
            f"{RECALL_NONE}, is the same place whatever its parts say (docs/method.md).")
