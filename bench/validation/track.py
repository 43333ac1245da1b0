"""pcmapq track on CARMEN logs with drift injected from a known scan: do the curves stay flat
before it, fall after it, and does the worst drop land on it?

For each log the run is tracked twice against the map of its corrected poses (the truth):
once at the corrected poses, once at poses integrated again with a gain error of ``LEVEL``
on every rotation and translation increment after scan ``k`` (the middle scan; see
:mod:`testkit.drift`), so both runs' maps are the same up to scan k.

    python -m bench.validation --only track
"""

from __future__ import annotations

import io
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pcmapq.settings import Settings
from pcmapq.track import open_run, planar_of, planar_poses, step_ends, track_run, travelled
from pcmapq.track.drop import Drop
from pcmapq.track.timeline import Step
from testkit.drift import increments, integrate

from .common import Case, Record, Section

#: The logs, the step rule (scans), the gain error and where it starts (share of the scans).
LOGS = ("fhw-corrected.log.gz", "aces-corrected.log.gz")
EVERY = 20
LEVEL = 0.02
START_SHARE = 0.5
#: The figures compared: the mean precision (the worst drop's), each detector's
#: quality, the share of the map's walls within 0.1 m of the truth's, and how far the newest
#: part of the map lies off the truth.
FIGURES = ("precision", "harris_quality", "hough_quality", "sift_quality",
           "wall_precision@0.1m", "local_offset_m")


@dataclass(frozen=True)
class Curves:
    """Both runs of one log: ``k`` the first drifted scan, ``k_step`` the first step whose map
    holds a drifted scan; the steps of each run, the drifted run's worst drop, seconds."""

    log: str
    k: int
    k_step: int
    corrected: list[Step]
    drifted: list[Step]
    drop: Drop | None
    seconds: float

    def values(self, steps: list[Step], figure: str) -> np.ndarray:
        return np.array([np.nan if s.figures.get(figure) is None else s.figures[figure]
                         for s in steps])

    def before_gap(self) -> float:
        """Largest difference of a compared figure between the runs before ``k_step``."""
        return max(float(np.nanmax(np.abs(self.values(self.drifted, f)[:self.k_step]
                                          - self.values(self.corrected, f)[:self.k_step]),
                                   initial=0.0)) for f in FIGURES)

    def summary(self) -> dict:
        last = {f"{f}_end": [float(self.values(r, f)[-1]) for r in (self.corrected,
                                                                     self.drifted)]
                for f in FIGURES}
        return {"k_step": self.k_step, "before_gap": self.before_gap(),
                "drop_start": None if self.drop is None else self.drop.start, **last}


def drifted_poses(poses: np.ndarray, k: int, level: float) -> np.ndarray:
    """(K, 4, 4) planar poses integrated again with the gain ``1 + level`` on the increments
    after scan k (so scans 0..k keep their poses)."""
    xyt = planar_of(poses)
    steps = increments(xyt)
    steps[k:] *= 1.0 + level
    return planar_poses(integrate(xyt[0], steps))


def measure(log: Path) -> Curves:
    """Track the log at its corrected and at its drifted poses against its corrected map."""
    start = time.perf_counter()
    run = open_run(log)
    k = int(START_SHARE * len(run))
    ends = step_ends(len(run), EVERY, distance=travelled(run.poses))
    k_step = int(np.searchsorted(ends, k + 2))  # the first map holding scan k + 1
    corrected = track_run(run, log, Settings(), ends)
    drifted = track_run(replace(run, poses=drifted_poses(run.poses, k, LEVEL)), log,
                        Settings(), ends)
    return Curves(log.name, k, k_step, corrected.steps, drifted.steps, drifted.drop,
                  time.perf_counter() - start)


def cases(data: Path) -> list[Case]:
    return [Case(f"track-{name.split('-')[0]}", lambda name=name: measure(data / "carmen" / name))
            for name in LOGS]


def picture(c: Curves) -> bytes:
    """Precision, wall precision and the newest part's offset of both runs against distance,
    k and the drop marked."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12, 4.2), layout="constrained")
    axes = fig.subplots(1, 3, sharex=True)
    distance = np.array([s.distance_m for s in c.corrected])
    for ax, figure in zip(axes, ("precision", "wall_precision@0.1m", "local_offset_m"),
                          strict=True):
        ax.plot(distance, c.values(c.corrected, figure), ".-", label="corrected poses")
        ax.plot(distance, c.values(c.drifted, figure), ".-", label=f"{100 * LEVEL:g} % gain "
                f"error after scan {c.k}")
        ax.axvline(c.drifted[c.k_step].distance_m, color="k", lw=0.8, ls=":",
                   label="first step with a drifted scan")
        if c.drop is not None:
            ax.axvline(c.drifted[c.drop.start].distance_m, color="#ee6677", lw=1.2,
                       label="worst drop starts")
        ax.set_ylim(0, 1.02 if figure != "local_offset_m" else None)
        ax.set_title(figure + (" [m]" if figure.endswith("_m") else ""), fontsize=9)
        ax.set_xlabel("distance travelled [m]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(c.log, fontsize=10)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    return buffer.getvalue()


def _min_after(c: Curves, figure: str, threshold: float) -> str:
    """From which step on the corrected run's figure stays at or above ``threshold``."""
    values = c.values(c.corrected, figure)
    below = np.flatnonzero(~(values >= threshold))
    if len(below) == 0:
        return "every step"
    if below[-1] == len(values) - 1:
        return "never"
    return f"step {below[-1] + 1} on ({c.corrected[below[-1] + 1].distance_m:.0f} m)"


def table(c: Curves) -> str:
    head = ["step", "scans", "distance m", *(f"{f} corr / drift" for f in FIGURES)]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for a, b in zip(c.corrected, c.drifted, strict=True):
        mark = " (k)" if a.step == c.k_step else (" (drop)" if c.drop is not None and
                                                   a.step == c.drop.start else "")
        cells = [f"{a.step}{mark}", str(a.scans), f"{a.distance_m:.0f}"]
        for f in FIGURES:
            x, y = a.figures.get(f), b.figures.get(f)
            cells.append(("-" if x is None else f"{x:.3f}") + " / "
                         + ("-" if y is None else f"{y:.3f}"))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def section(data: Path, record: Record) -> Section:
    measured = [case.run(record) for case in cases(data)]
    text = ["## pcmapq track: drift injected at a known scan", "",
            f"Each log is tracked every {EVERY} scans (`pcmapq track LOG LOG --every {EVERY}`: "
            "its map so far against the map of all its corrected poses, inside the area its "
            "scans saw) twice: at its corrected poses, and at poses integrated again with a "
            f"{100 * LEVEL:g} % gain error on every rotation and translation increment after "
            "its middle scan k. The worst drop is the largest fall of the mean precision of "
            "Harris, Hough and SIFT (the rooms' precision, which falls as a growing map's rooms "
            "are drawn in part, aside) from its highest value so far (docs/metrics.md).", ""]
    files = {}
    for c in measured:
        stem = c.log.split("-")[0]
        drop = ("no drop" if c.drop is None else
                f"the worst drop starts at step {c.drop.start} ({c.drop.size:.3f} down to "
                f"step {c.drop.low}), {c.drop.start - c.k_step:+d} steps from the first "
                f"drifted step {c.k_step}")
        ends = {f: c.values(r, f)[-1] for f in ("precision", "wall_precision@0.1m")
                for r in (c.drifted,)}
        text += [f"### {c.log} ({len(c.corrected)} steps, k = scan {c.k}; both runs "
                 f"{c.seconds:.0f} s)", "",
                 f"![{c.log}](img/track-{stem}.png)", "",
                 f"Before the drift the two runs differ by at most {c.before_gap():.3f} in "
                 f"any compared figure; {drop}. At the end the drifted map's precision is "
                 f"{ends['precision']:.3f} and its wall precision at 0.1 m "
                 f"{ends['wall_precision@0.1m']:.3f}. At the corrected poses the wall "
                 "precision at 0.1 m stays at or above 0.95 from "
                 f"{_min_after(c, 'wall_precision@0.1m', 0.95)}, the detectors' mean "
                 f"precision from {_min_after(c, 'precision', 0.95)} and Harris's quality "
                 f"from {_min_after(c, 'harris_quality', 0.95)}. The newest part of the map "
                 "lies at most "
                 f"{np.nanmax(c.values(c.corrected, 'local_offset_m')):.3f} m off the truth "
                 "at the corrected poses, at most "
                 f"{np.nanmax(c.values(c.drifted, 'local_offset_m')[:c.k_step]):.3f} m at the "
                 "drifted ones before the drift and at least "
                 f"{np.nanmin(c.values(c.drifted, 'local_offset_m')[c.k_step:]):.3f} m from "
                 "the first drifted step on.", "",
                 table(c), ""]
        files[f"img/track-{stem}.png"] = picture(c)
    return Section("\n".join(text), files)
