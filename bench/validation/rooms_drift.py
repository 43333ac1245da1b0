"""Rooms under drift: the CARMEN drift ladder (:mod:`testkit.drift`) on six logs, each
with several drift draws (seeds), scored by the rooms detector alone: does its quality fall as
the poses drift?"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

from pcmapq.report.text import score
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from testkit import drift

from .common import Case, Record, Section, header, row

LOGS = ("intel", "fhw", "freiburg-079", "aces", "csail", "orebro")
LEVELS = drift.DEFAULT_LEVELS
#: The drift draws of every level: seed 0 is the CARMEN section's ladder.
SEEDS = (0, 1, 2, 3, 4)
SETTINGS = Settings(alignment=AlignmentConfig(force=True),
                    matching=MatchingConfig(detectors=("rooms",)))
#: The least fall the issue asks of the rooms' quality along a ladder (Spearman's rho).
RHO = -0.9


def cases(data: Path) -> list[Case]:
    """Log by log, seed by seed, level by level."""
    return [Case(f"drift-rooms-{log}-{100 * level:g}" + (f"-seed{seed}" if seed else ""),
                 lambda log=log, level=level, seed=seed: drift.rung(
                     data / "carmen" / f"{log}-corrected.log.gz", level, seed,
                     settings=SETTINGS))
            for log in LOGS for seed in SEEDS for level in LEVELS]


def rho(levels: list[float], values: list[float | None]) -> float:
    """Spearman's rho of the values against the levels, an undefined value counted as 0 (no
    room matched where none was found)."""
    return float(spearmanr(levels, [0.0 if v is None else v for v in values])[0])


def rho_cell(value: float | None) -> str:
    """A rank correlation for a table: bold where above RHO, "n/a" where undefined (bold where
    the figure is the same at every level: it does not fall)."""
    if value is None:
        return "n/a"
    if np.isnan(value):
        return "**n/a**"
    return f"{value:.2f}" if value <= RHO else f"**{value:.2f}**"


def section(data: Path, record: Record) -> Section:
    """One row per log: the rooms' quality at each level, averaged over the seeds, and the rank
    correlations with the drift of that mean and of each seed's ladder."""
    got = [case.run(record) for case in cases(data)]
    per_log = len(SEEDS) * len(LEVELS)
    lines, weak = [], []
    for i, log in enumerate(LOGS):
        ladders = [got[i * per_log + k * len(LEVELS):i * per_log + (k + 1) * len(LEVELS)]
                   for k in range(len(SEEDS))]
        levels = [r.level for r in ladders[0]]
        quality = [[0.0 if r.quality["rooms"] is None else r.quality["rooms"] for r in rungs]
                   for rungs in ladders]
        f1 = [[0.0 if r.f1["rooms"] is None else r.f1["rooms"] for r in rungs]
              for rungs in ladders]
        mean_q, mean_f = np.mean(quality, axis=0), np.mean(f1, axis=0)
        each = [rho(levels, q) for q in quality]
        weak += [row([log, str(seed), " ".join(score(v, 2) for v in quality[k]),
                      " ".join(str(r.figures["detectors"]["rooms"]["truth_features"])
                               for r in ladders[k])])
                 for k, seed in enumerate(SEEDS) if each[k] > RHO]
        truth_rooms = ladders[0][0].figures["detectors"]["rooms"]["truth_features"]
        lines.append(row([
            log, str(truth_rooms), " ".join(score(float(q), 2) for q in mean_q),
            rho_cell(rho(levels, list(mean_q))), f"{rho(levels, list(mean_f)):.2f}",
            " ".join(rho_cell(r) for r in each), f"{sum(r <= RHO for r in each)} of {len(each)}"]))
    return Section("\n".join([
        "## Rooms under drift: the CARMEN ladders scored by rooms", "",
        "The drift ladder of the CARMEN section (the same reference and drifted maps, levels "
        f"{', '.join(f'{100 * v:g}' for v in LEVELS)} %) on six logs, each level drawn with "
        f"seeds {', '.join(map(str, SEEDS))} (seed 0 is the CARMEN section's ladder; each seed "
        "is another draw of the per-step gain errors), scored by the rooms detector alone "
        "(`--detectors rooms`, `force`). rho: Spearman's rank correlation of the figure with "
        "the drift level (-1: it falls at every step); bold where above "
        f"{RHO}. Mean: the figure averaged over the seeds at each level (a level's expected "
        "figure); per seed: each draw's own ladder. An undefined quality (no truth room seen "
        "whole enough to count) counts as 0.", "",
        header(["log", "truth rooms", "mean quality per level", "rho mean quality",
                "rho mean f1", "rho quality per seed", "seeds at most " + f"{RHO}"]),
        *lines, "",
        *([] if not weak else [
            "The ladders of the draws whose quality does not fall to rho "
            f"{RHO} (the quality per level, and the truth rooms counted at each level, those "
            "seen whole enough inside the drifted map's footprint):", "",
            header(["log", "seed", "quality per level", "truth rooms counted per level"]),
            *weak, ""]),
        "A ladder's last levels (pose errors of several metres) match a few rooms or none; "
        "which few depends on where the alignment of the whole drifted map puts it, so one "
        "draw's order among those levels is chance. The mean over the draws is the figure a "
        "level gives on average.",
    ]))
