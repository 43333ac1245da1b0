"""Rooms under drift: the CARMEN drift ladder (:mod:`pcmapq.testing.drift`) on six logs,
scored by the rooms detector alone: does its quality fall as the poses drift?"""

from __future__ import annotations

from pathlib import Path

from scipy.stats import spearmanr

from pcmapq.report.text import score
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from pcmapq.testing import drift

from .common import Case, Record, Section, header, row

LOGS = ("intel", "fhw", "freiburg-079", "aces", "csail", "orebro")
LEVELS = drift.DEFAULT_LEVELS
SEED = 0
SETTINGS = Settings(alignment=AlignmentConfig(force=True),
                    matching=MatchingConfig(detectors=("rooms",)))
#: The least fall the issue asks of the rooms' quality along a ladder (Spearman's rho).
RHO = -0.9


def cases(data: Path) -> list[Case]:
    return [Case(f"drift-rooms-{log}-{100 * level:g}",
                 lambda log=log, level=level: drift.rung(
                     data / "carmen" / f"{log}-corrected.log.gz", level, SEED,
                     settings=SETTINGS))
            for log in LOGS for level in LEVELS]


def rho(levels: list[float], values: list[float | None]) -> float:
    """Spearman's rho of the values against the levels, an undefined value counted as 0 (no
    room matched where none was found)."""
    return float(spearmanr(levels, [0.0 if v is None else v for v in values])[0])


def section(data: Path, record: Record) -> Section:
    """One row per log: the rooms' quality and f1 at each level, and their rank correlation
    with the drift."""
    got = [case.run(record) for case in cases(data)]
    lines = []
    for i, log in enumerate(LOGS):
        rungs = got[i * len(LEVELS):(i + 1) * len(LEVELS)]
        levels = [r.level for r in rungs]
        quality = [r.quality["rooms"] for r in rungs]
        f1 = [r.f1["rooms"] for r in rungs]
        rho_q, rho_f = rho(levels, quality), rho(levels, f1)
        truth_rooms = rungs[0].figures["detectors"]["rooms"]["truth_features"]
        lines.append(row([
            log, str(truth_rooms), " ".join(score(q, 2) for q in quality),
            " ".join(score(f, 2) for f in f1),
            f"{rho_q:.2f}" if rho_q <= RHO else f"**{rho_q:.2f}**", f"{rho_f:.2f}"]))
    return Section("\n".join([
        "## Rooms under drift: the CARMEN ladders scored by rooms", "",
        "The drift ladder of the CARMEN section (the same reference and drifted maps, levels "
        f"{', '.join(f'{100 * v:g}' for v in LEVELS)} %, seed {SEED}) on six logs, scored by "
        "the rooms detector alone (`--detectors rooms`, `force`). rho: Spearman's rank "
        "correlation of the figure with the drift level (-1: it falls at every step); bold "
        f"where the quality's is above {RHO}.", "",
        header(["log", "truth rooms", "quality per level", "f1 per level", "rho quality",
                "rho f1"]),
        *lines,
    ]))
