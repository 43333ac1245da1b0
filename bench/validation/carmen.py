"""CARMEN: the drift ladder (:mod:`testkit.drift`) on the Intel and FHW logs: does
pcmapq rank maps by how much their poses drifted?"""

from __future__ import annotations

from pathlib import Path

from pcmapq.io.carmen import DEFAULT_MAX_RANGE
from pcmapq.settings import Settings
from testkit import drift

from .common import Case, Record, Section, span

#: The logs of the ladder, and its levels (relative gain errors) and seed.
LOGS = ("intel-corrected.log.gz", "fhw-corrected.log.gz")
LEVELS = drift.DEFAULT_LEVELS
SEED = 0


def worse_steps(rungs: list[drift.Rung]) -> list[str]:
    """The steps where a figure other than f1 does not get worse: a quality, a precision, the
    fitness or F@0.1 that does not fall, a distance that does not grow."""
    figures: dict[str, tuple[list[float | None], int]] = {
        "fitness": ([r.fitness for r in rungs], -1), "F@0.1": ([r.f_at_01 for r in rungs], -1),
        "acc mean": ([r.accuracy_mean_m for r in rungs], 1),
        "comp mean": ([r.completeness_mean_m for r in rungs], 1),
        "Chamfer": ([r.chamfer_m for r in rungs], 1)}
    for name in rungs[0].quality:
        figures[f"q {name}"] = ([r.quality[name] for r in rungs], -1)
        figures[f"prec {name}"] = ([r.precision[name] for r in rungs], -1)
    out = []
    for label, (values, sign) in figures.items():
        for a, b, va, vb in zip(rungs, rungs[1:], values, values[1:], strict=False):
            if va is not None and vb is not None and not sign * (vb - va) > 0:
                out.append(f"{label} from {100 * a.level:g} to {100 * b.level:g} % "
                           f"({va:.3f}, {vb:.3f})")
    return out


def cases(data: Path) -> list[Case]:
    return [Case(f"carmen-{log.split('-')[0]}-{100 * level:g}",
                 lambda log=log, level=level: drift.rung(data / "carmen" / log, level, SEED,
                                                         settings=Settings()))
            for log in LOGS for level in LEVELS]


def section(data: Path, record: Record) -> Section:
    """One table per log, and what falls."""
    got = [case.run(record) for case in cases(data)]
    ladders = {log: got[i * len(LEVELS):(i + 1) * len(LEVELS)] for i, log in enumerate(LOGS)}
    lines = [
        "## CARMEN drift ladder: maps from drifted poses vs the corrected map", "",
        "Each log's scans placed along its corrected poses make the reference; the same scans "
        "along a trajectory re-integrated with gain errors of level e (systematic e plus "
        f"random N(0, e) per step, seed {SEED}) make the worse maps, scored as `pcmapq eval` "
        "scores them by default; a map it refuses (verdict \"another place\") is scored again "
        "with `force` for its figures. 2D clouds of the laser endpoints (no views: nothing "
        f"says what the robot saw), max range {DEFAULT_MAX_RANGE:g} m. "
        "`python -m bench.validation.drift LOG` runs the ladder on any log.",
    ]
    for log, rungs in ladders.items():
        lines += ["", f"### {log}", "", drift.markdown(rungs), "", drift.falls_text(rungs)]
    large = [level for level in LEVELS if level >= 0.01]
    errors = "; ".join(
        f"{log.split('-')[0]} {span([r.pose_error_m for r in rungs if r.level in large], 0)} m"
        for log, rungs in ladders.items())
    steps = {log.split("-")[0]: worse_steps(rungs) for log, rungs in ladders.items()}
    listed = "; ".join(f"{log}: " + (", ".join(s) if s else "none") for log, s in steps.items())
    top = LEVELS[-1]
    sift = ", ".join(f"{log.split('-')[0]} {rungs[-1].quality['sift']:.3f}"
                     for log, rungs in ladders.items())
    lines += [
        "", f"Pose errors at {', '.join(f'{100 * v:g}' for v in large)} %: {errors}. Steps "
        f"where a quality, a precision, the fitness or F@0.1 does not fall or a distance does "
        f"not grow: {listed}. At the largest drifts a recall under the "
        f"{Settings().matching.threshold} m matching threshold has a floor set by how many "
        "features the "
        "map has: a drifted map smears each wall over a band and has more features, so more of "
        "them land within the threshold of a truth feature by chance. A SIFT pair must also "
        "look alike (its descriptor gate, docs/method.md), so SIFT falls like the others: its "
        f"quality at {100 * top:g} % is {sift}.",
    ]
    return Section("\n".join(lines))
