"""The runs a ratio is made of (:mod:`bench.ratios`): commands timed in fresh processes, the two
sides alternated, each side's best kept; a case's inputs written once into the cache."""

from __future__ import annotations

import shutil
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from bench.bench_clouds import measured


@dataclass(frozen=True)
class Ratio:
    """One measured ratio: ``name`` (case/figure), ``value`` = ``ours`` / ``theirs`` (lower is
    better), what each side is, and the issue's target when it sets one."""

    name: str
    value: float
    ours: str
    theirs: str
    target: float | None = None

    def row(self) -> str:
        target = "" if self.target is None else f"{self.target:g}"
        return f"| {self.name} | {self.value:.2f} | {target} | {self.ours} | {self.theirs} |"


def best(cmd: list[str], repeat: int) -> tuple[float, float]:
    """Best wall seconds and best peak GB of ``cmd`` over ``repeat`` fresh processes."""
    runs = [measured(cmd)[:2] for _ in range(repeat)]
    return min(r[0] for r in runs), min(r[1] for r in runs)


def paired(first: list[str], second: list[str], repeat: int
           ) -> tuple[tuple[float, float], tuple[float, float]]:
    """(seconds, GB) of both commands, run alternately, each side's best of ``repeat``."""
    a, b = [], []
    for _ in range(repeat):
        a.append(measured(first)[:2])
        b.append(measured(second)[:2])
    return ((min(x[0] for x in a), min(x[1] for x in a)),
            (min(x[0] for x in b), min(x[1] for x in b)))


def eval_cmd(map_path: Path, truth: Path, out: Path, *extra: str) -> list[str]:
    """``pcmapq eval`` of ``map_path`` against ``truth`` in a fresh Python, its JSON to ``out``."""
    return [sys.executable, "-m", "pcmapq", "eval", str(map_path), str(truth), "--json",
            str(out), *extra]


def written(folder: Path, write: Callable[[Path], object]) -> Path:
    """``folder``, written by ``write(folder)`` the first time: into a sibling folder renamed
    once whole, so that an interrupted run leaves no half-written case to be read later."""
    if not folder.is_dir():
        part = folder.with_name(folder.name + ".part")
        shutil.rmtree(part, ignore_errors=True)
        part.mkdir(parents=True)
        write(part)
        part.rename(folder)
    return folder
