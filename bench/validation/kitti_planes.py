"""KITTI 00's 3D structures under a pitch drift: the map of its first 20 scans at KITTI's poses
against itself with each scan's pose turned about its lateral axis, more at every level of the
ladder, scored as ``pcmapq eval`` scores two 3D clouds: does the planes' f1 fall step by step,
and what do the structures add to the evaluation's time?"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import numpy as np

from pcmapq.io.writers import write_cloud
from pcmapq.mapping import build_map_from_poses
from pcmapq.report.text import score
from pcmapq.settings import NoRefConfig, Settings
from testkit.kitti import pitched
from testkit.realdata.ladders3d import rho as rank_rho
from testkit.runs import Run, f_at, timed_evaluate

from .common import Case, Record, Section, header, row
from .kitti import reference_map

#: Scans of the maps (the first ones of kitti00/velodyne).
SCANS = 20
#: Pitch per scan of each level, degrees: scan k is turned k times this.
LEVELS = (0.0, 0.05, 0.1, 0.2, 0.4)
#: The default settings but the no-reference figures (their time is another section's).
SETTINGS = Settings(noref=NoRefConfig(enabled=False))
#: The least fall the issue asks of the planes' f1 along the ladder (Spearman's rho).
RHO = -0.9


@dataclass(frozen=True)
class Rung:
    """One level: the evaluation, and (at the last level) the same without the structures."""

    level: float
    run: Run
    without: Run | None = None

    def summary(self) -> dict:
        return self.run.summary()


@lru_cache(maxsize=1)
def _reference(folder: Path) -> tuple[np.ndarray, np.ndarray]:
    """The map of the first scans at KITTI's poses, and those poses (built once)."""
    return reference_map(folder, SCANS)


def measure(folder: Path, level: float, timed: bool = False) -> Rung:
    """The pitched map of one level scored against the reference map (``timed``: also
    without the structures)."""
    truth, poses = _reference(folder)
    cloud = truth if level == 0 else build_map_from_poses(folder / "velodyne",
                                                          pitched(poses, level),
                                                          max_scans=SCANS).points
    with tempfile.TemporaryDirectory(prefix="pcmapq_kitti_planes_") as tmp:
        write_cloud(Path(tmp) / "truth.ply", truth)
        write_cloud(Path(tmp) / "map.ply", cloud)
        run = timed_evaluate(Path(tmp) / "map.ply", Path(tmp) / "truth.ply", SETTINGS)
        off = replace(SETTINGS, structures=replace(SETTINGS.structures, enabled=False))
        without = timed_evaluate(Path(tmp) / "map.ply", Path(tmp) / "truth.ply", off) \
            if timed else None
    return Rung(level, run, without)


def cases(data: Path) -> list[Case]:
    return [Case(f"kitti-planes-{level:g}",
                 lambda level=level: measure(data / "kitti00", level, level == LEVELS[-1]))
            for level in LEVELS]


def _f1(rung: Rung, name: str) -> float | None:
    return rung.run.result.structures.detectors[name].matching.f1


def section(data: Path, record: Record) -> Section:
    """One row per level: the 3D registration, the planes' and plane lines' scores, the
    wall band's Harris f1 and the 3D F-score; the planes' f1's rank correlation with the
    level; the evaluation's time with and without the structures."""
    rungs: list[Rung] = [case.run(record) for case in cases(data)]
    lines = []
    for r in rungs:
        res = r.run.result
        planes = res.structures.detectors["planes"].matching
        reg = res.registration_3d
        lines.append(row([
            f"{r.level:g}", f"{r.level * (SCANS - 1):.2f}", f"{reg.fitness:.3f}",
            f"{planes.truth_structures} / {planes.map_structures} / {planes.matched}",
            f"{score(planes.quality, 2)} / {score(planes.precision, 2)}",
            f"**{score(planes.f1, 2)}**",
            "-" if not planes.matched else f"{np.abs(planes.displacement).mean():.3f}",
            "-" if not planes.matched else f"{planes.angle.mean():.2f}",
            score(_f1(r, "plane_lines"), 2),
            score(res.detectors["harris"].matching.f1, 2),
            score(f_at(res, 0.1, three_d=True), 2)]))
    levels = [r.level for r in rungs]
    line_f1 = [_f1(r, "plane_lines") or 0.0 for r in rungs]
    lines_rho = rank_rho(levels, line_f1)
    f1 = [_f1(r, "planes") or 0.0 for r in rungs]
    rho = rank_rho(levels, f1)
    falls = ("falls at every step" if all(a > b for a, b in zip(f1, f1[1:], strict=False))
             else "does not fall at every step")
    last = rungs[-1]
    truth_lines = last.run.result.structures.detectors["plane_lines"].matching.truth_structures
    steps = all(a > b for a, b in zip(line_f1, line_f1[1:], strict=False))
    lines_words = (f"(rho {lines_rho:.2f}; the truth has {truth_lines}) ranks them too"
                   f"{', falling at every step' if steps else ', though not step by step'}"
                   if lines_rho <= RHO else
                   f"does not (rho {lines_rho:.2f}): the truth has {truth_lines}, too few to rank "
                   "the levels")
    on, off = last.run.seconds, last.without.seconds
    return Section("\n".join([
        "## KITTI 00's 3D structures under a pitch drift", "",
        f"The map of the first {SCANS} scans of `kitti00/velodyne` at KITTI's poses (as the "
        "KITTI section builds it) is the truth; each map is the same scans with scan k's pose "
        "turned k x level degrees about its lateral axis (the velodyne's y), a pitch drift "
        "growing scan by scan, the largest at the last scan. `pcmapq eval map.ply truth.ply "
        "--no-noref`: both registered in 3D, then their planes and plane "
        "lines found and matched one to one (docs/metrics.md#3d-structures-two-3d-clouds; "
        "5 degrees, 0.5 m). Planes: truth / map / matched, quality / precision, f1, the "
        "matched planes' mean displacement size (m) and angle (degrees).", "",
        header(["pitch per scan (deg)", "at the last scan (deg)", "3D fitness",
                "planes truth / map / matched", "planes q / p", "planes f1",
                "displacement (m)", "angle (deg)", "plane lines f1", "Harris f1 (wall band)",
                "F@0.1 m 3D"]),
        *lines, "",
        f"The planes' f1 {falls}: Spearman's rho with the level {rho:.2f} (the issue asks "
        f"{RHO} or less). The plane lines' f1 {lines_words}. At the "
        f"last level the evaluation took {on:.0f} s with the "
        f"structures and {off:.0f} s without them ({on / off:.2f} times; `python -m bench "
        "--only structures` measures the ratio in fresh processes, docs/benchmarks.md).",
    ]))
