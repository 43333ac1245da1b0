"""Where a map breaks: does the consistency map (each region of the map aligned on its own,
:mod:`pcmapq.align.regions`) report the displacement a known distortion put there?

- Plans bent like odometry drift (:func:`testkit.synth.bend`) and plans whose eastern
  half was turned about the plan's middle: the displacement that undoes the distortion is known
  at every map point, so each region's expected offset is the mean of its points'.
- CARMEN logs whose poses drift from a known scan k on (every increment after it scaled by
  1 + level, :func:`bench.validation.track.drifted_poses`), against the map of their corrected
  poses: each drifted endpoint's corrected position is the same beam at the corrected pose.

Reported per case: the verdict, the regions held, the correlation between expected and reported
offsets (x and y together), the median offset of the regions made of scans before k and of
those after it.

    python -m bench.validation --only consistency
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import PointMap
from pcmapq.io.carmen import endpoints, read_flaser
from pcmapq.report.plot import figure_bytes, vectorial_figure
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from testkit import synth
from testkit.drift import increments, integrate

from .common import Case, Record, Section

#: Scored with --force (a verdict of another place is reported, not raised), no detectors.
SETTINGS = Settings(alignment=AlignmentConfig(force=True), matching=MatchingConfig(detectors=()))
#: The map frame of the synthetic maps: ``p_truth = TRUE(p_map)``.
TRUE = Similarity2D(3.0, -2.0, np.radians(37.0))
BENDS = (0.05, 0.1, 0.2)  # degrees per metre
BREAKS = (10.0, 20.0, 30.0)  # degrees, the eastern half about (12, 8) m
SEEDS = (0, 1, 2)
#: CARMEN: logs, the drift level and where it starts (share of the scans), readings kept.
LOGS = ("fhw-corrected.log.gz", "aces-corrected.log.gz", "intel-corrected.log.gz")
LEVEL, START_SHARE, MAX_RANGE = 0.02, 0.5, 30.0
#: A region is "after k" when at least half its points come from drifted scans, "before k"
#: when none does.
AFTER_SHARE = 0.5


@dataclass(frozen=True)
class Measured:
    """One distorted map: its verdict, confidence, regions held, the correlation of expected
    and reported offsets over the held regions, the largest held offset (m), the median held
    offset before and after k (CARMEN; None for plans), the largest expected displacement (m),
    seconds; ``figure``: its regions panel (PNG) for the document, or None."""

    name: str
    verdict: str
    confidence: float
    regions: int
    held: int
    correlation: float
    largest_m: float | None
    before_m: float | None
    after_m: float | None
    displacement_m: float
    seconds: float
    figure: bytes | None = None

    def summary(self) -> dict:
        return {k: v for k, v in self.__dict__.items() if k not in ("seconds", "figure")}


def _measure(name: str, drawn: np.ndarray, where: np.ndarray, truth: Path,
             drifted: np.ndarray | None = None, picture: bool = False) -> Measured:
    """Score ``drawn`` (N, 2, map frame) against ``truth``; ``where``: each point's true place
    (N, 2, truth frame); ``drifted``: (N,) whether a point comes from a drifted scan."""
    start = time.perf_counter()
    source = PointMap(Path(name), np.column_stack([drawn, np.zeros(len(drawn))]), False)
    result = evaluate(source, truth, SETTINGS)
    c = result.consistency
    placed = result.transform.apply(drawn)
    cell = np.floor(placed / c.tile_m).astype(np.int64)
    expected, after = [], []
    for centre in c.centre:
        mine = (cell == np.floor(centre / c.tile_m).astype(np.int64)).all(axis=1)
        expected.append((where[mine] - placed[mine]).mean(axis=0))
        after.append(drifted[mine].mean() if drifted is not None else 0.0)
    expected, after = np.array(expected).reshape(-1, 2), np.array(after)
    held = c.held
    offsets = c.offset_m
    r = (float(np.corrcoef(expected[held].ravel(), c.offset[held].ravel())[0, 1])
         if held.sum() > 2 else float("nan"))
    k = c.largest()

    def median(mask: np.ndarray) -> float | None:
        return float(np.median(offsets[mask & held])) if (mask & held).any() else None

    figure = None
    if picture:
        figure = figure_bytes(vectorial_figure(result), "png")
    return Measured(name, result.overlap.verdict, result.overlap.confidence, len(offsets),
                    int(held.sum()), r, None if k is None else float(offsets[k]),
                    median(after == 0) if drifted is not None else None,
                    median(after >= AFTER_SHARE) if drifted is not None else None,
                    float(np.hypot(*(where - placed).T).max()),
                    time.perf_counter() - start, figure)


def _plan_truth(seed: int, folder: Path) -> Path:
    path = folder / f"plan{seed}.npy"
    points = synth.wall_points(synth.building_plan(seed))
    np.save(path, np.column_stack([points, np.zeros(len(points))]))
    return path


def bent(seed: int, degrees_per_metre: float, picture: bool = False) -> Measured:
    """The plan's walls drawn bent by ``degrees_per_metre`` about its lower-left corner."""
    where = synth.wall_points(synth.building_plan(seed), seed=1)
    with tempfile.TemporaryDirectory(prefix="consistency_") as tmp:
        return _measure(f"plan {seed} bent {degrees_per_metre:g} deg/m",
                        TRUE.inverse().apply(synth.bend(where, degrees_per_metre)), where,
                        _plan_truth(seed, Path(tmp)), picture=picture)


def broken(seed: int, degrees: float, picture: bool = False) -> Measured:
    """The plan's walls with the eastern half (x > 12 m) turned by ``degrees`` about
    (12, 8) m."""
    where = synth.wall_points(synth.building_plan(seed), seed=1)
    drawn = where.copy()
    east = drawn[:, 0] > 12.0
    pivot = np.array([12.0, 8.0])
    drawn[east] = Similarity2D(0, 0, np.radians(degrees)).apply(drawn[east] - pivot) + pivot
    with tempfile.TemporaryDirectory(prefix="consistency_") as tmp:
        return _measure(f"plan {seed}, east half turned {degrees:g} deg",
                        TRUE.inverse().apply(drawn), where, _plan_truth(seed, Path(tmp)),
                        picture=picture)


def carmen(log: Path, picture: bool = False) -> Measured:
    """The log's endpoints at poses drifting from scan k on, against its corrected map."""
    poses, ranges, angles = read_flaser(log)
    k = int(START_SHARE * len(poses))
    steps = increments(poses)
    steps[k:] *= 1.0 + LEVEL
    moved = integrate(poses[0], steps)
    where = endpoints(poses, ranges, angles, MAX_RANGE)
    drawn = endpoints(moved, ranges, angles, MAX_RANGE)
    counts = np.count_nonzero((ranges > 0) & (ranges <= MAX_RANGE), axis=1)
    drifted = np.repeat(np.arange(len(poses)) > k, counts)
    with tempfile.TemporaryDirectory(prefix="consistency_") as tmp:
        truth = Path(tmp) / "corrected.npy"
        np.save(truth, np.column_stack([where, np.zeros(len(where))]))
        return _measure(f"{log.name.split('-')[0]}, {100 * LEVEL:g} % drift from scan {k}",
                        drawn, where, truth, drifted, picture)


def cases(data: Path) -> list[Case]:
    plans = [Case(f"consistency-bent-{s}-{b:g}", lambda s=s, b=b: bent(s, b, s == 0 and b == 0.2))
             for s in SEEDS for b in BENDS]
    plans += [Case(f"consistency-broken-{s}-{d:g}",
                   lambda s=s, d=d: broken(s, d, s == 0 and d == 20.0))
              for s in SEEDS for d in BREAKS]
    logs = [Case(f"consistency-{name.split('-')[0]}",
                 lambda name=name: carmen(data / "carmen" / name, name.startswith("fhw")))
            for name in LOGS]
    return plans + logs


def _cell(value: float | None, digits: int = 2) -> str:
    return "-" if value is None or value != value else f"{value:.{digits}f}"


def section(data: Path, record: Record) -> Section:
    rows = [case.run(record) for case in cases(data)]
    files = {f"img/consistency_{i}.png": m.figure for i, m in enumerate(rows) if m.figure}
    text = [
        "## Where a map breaks: the consistency map on known distortions", "",
        "Each scored map's regions (4 m tiles of the truth frame) are aligned to the truth on "
        "their own (`consistency` in the JSON, `--regions`). On maps distorted by a known "
        "amount, the displacement that undoes the distortion is known at every point; a "
        "region's expected offset is the mean over its points. *r*: the correlation of "
        "expected and reported offsets (x and y together) over the held regions; *largest*: "
        "the largest held offset. Plans: the synthetic building as 2D wall points, bent about "
        "its lower-left corner, or its eastern half turned about its middle, against its own "
        "walls. CARMEN: the log's endpoints (readings up to 30 m) at poses whose increments "
        f"after scan k (half the log) are scaled by {1 + LEVEL:g}, against the map of the "
        "corrected poses; *before k* and *after k*: the median held offset of the regions made "
        "of scans before k only, and of those at least half made of scans after it. Every map "
        "is scored with `--force` and no detectors.", "",
        "| map | verdict | confidence | regions (held) | largest expected displacement (m) "
        "| largest offset (m) | r | before k (m) | after k (m) | s |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for m in rows:
        text.append(f"| {m.name} | {m.verdict} | {m.confidence:.2f} | {m.regions} ({m.held}) "
                    f"| {m.displacement_m:.2f} | {_cell(m.largest_m)} | {_cell(m.correlation)} "
                    f"| {_cell(m.before_m)} | {_cell(m.after_m)} | {m.seconds:.1f} |")
    for rel in files:
        text += ["", f"![regions panel]({rel})"]
    return Section("\n".join(text), files)
