"""pcmapq track on a ROS recording made from a CARMEN log: the maps a SLAM system would publish
(nav_msgs/OccupancyGrid, the map of the scans so far every EVERY scans, at their log times) and
the log's scans (sensor_msgs/LaserScan), with a gain error injected on every pose increment
after the middle scan. Does the worst drop start when the drift does?

The grids: the endpoints so far as occupied cells (0.05 m), the area the scans saw (their
views, as pcmapq track draws them) as free, the rest unknown. Written as a ROS 2 MCAP bag with
rosbags' own writer (testkit.recordings), then scored as a user's recording is:
``pcmapq track RUN.mcap LOG`` against the map of the log's corrected poses.

    python -m bench.validation --only recording
"""

from __future__ import annotations

import io
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pcmapq.core.bounds import bounds
from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.io.bag_scans import scans as bag_scans
from pcmapq.raster.draw import points_to_grid
from pcmapq.raster.seen import seen_on
from pcmapq.settings import Settings
from pcmapq.track import Recording, open_run, step_ends, track_recording, travelled
from pcmapq.track.drop import MIN_DROP
from pcmapq.track.timeline import Step
from testkit.recordings import Scan, write_recording

from .common import Case, Record, Section
from .track import LEVEL, START_SHARE, drifted_poses

#: The logs, the scans between published maps, the grids' cell, metres.
LOGS = ("fhw-corrected.log.gz",)
EVERY = 20
RESOLUTION = 0.05


@dataclass(frozen=True)
class Recorded:
    """One log's recording: the first drifted scan ``k`` and its time, the first published
    map holding it, the tracked steps, the worst drop's start, the recording's size, seconds."""

    log: str
    k: int
    k_time: float
    k_step: int
    steps: list[Step]
    drop_start: int | None
    scans: int
    laser_points: int
    bag_bytes: int
    seconds: float

    def summary(self) -> dict:
        return {"k_step": self.k_step, "k_time_s": self.k_time, "drop_start": self.drop_start,
                "drop_time_s": None if self.drop_start is None else
                self.steps[self.drop_start].time_s,
                "precision": [s.figures.get("precision") for s in self.steps]}


def grid_of(points: np.ndarray, seen, extent: tuple[np.ndarray, np.ndarray]) -> tuple:
    """The occupancy state (row 0 the top) and grid of a map so far: its points occupied, its
    views free, on one grid covering the whole log (``extent``: its corners, metres)."""
    (x0, y0), (x1, y1) = extent
    shape = (int(np.ceil((y1 - y0) / RESOLUTION)) + 1, int(np.ceil((x1 - x0) / RESOLUTION)) + 1)
    grid = MetricGrid(RESOLUTION, (float(x0), float(y0), 0.0), shape)
    occupied = points_to_grid(points[:, :2], grid)
    state = np.full(shape, UNKNOWN, dtype=np.int8)
    state[seen_on(seen, Similarity2D(), grid)] = FREE
    state[occupied] = OCCUPIED
    return state, grid


def measure(log: Path) -> Recorded:
    """Write the drifted log's recording and track it against the corrected log."""
    start = time.perf_counter()
    run = open_run(log)
    k = int(START_SHARE * len(run))
    drifted = replace(run, poses=drifted_poses(run.poses, k, LEVEL))
    ends = step_ends(len(run), EVERY, distance=travelled(run.poses))
    stamps = run.stamps - run.stamps[0]
    everything = next(iter(drifted.maps([len(run)])))
    extent = bounds(everything.points[:, :2])
    maps = []
    for end, (source, _) in zip(ends, drifted.steps(ends), strict=True):
        state, grid = grid_of(source.points, source.seen, extent)
        maps.append((float(stamps[end - 1]), state, grid))
    laser = run.scans
    scans = [Scan(float(stamps[i]), laser.ranges[i], float(laser.angles[i][0]),
                  float(laser.angles[i][1] - laser.angles[i][0])) for i in range(len(run))]
    with tempfile.TemporaryDirectory() as folder:
        bag = write_recording(Path(folder) / "run.mcap", maps, "mcap", scans=scans)
        size = bag.stat().st_size
        laser_points = sum(len(p) for _, p, _ in bag_scans(bag, "/scan"))
        tracked = track_recording(Recording(bag, "/map"), log, Settings())
    k_step = int(np.searchsorted(ends, k + 2))  # the first map holding scan k + 1
    drop = tracked.drop
    return Recorded(log.name, k, float(stamps[k + 1]), k_step, tracked.steps,
                    None if drop is None else drop.start, len(run), laser_points, size,
                    time.perf_counter() - start)


def cases(data: Path) -> list[Case]:
    return [Case(f"recording-{name.split('-')[0]}",
                 lambda name=name: measure(data / "carmen" / name)) for name in LOGS]


def picture(r: Recorded) -> bytes:
    """The detectors' mean precision of the published maps against the recording's time, the
    drift's start and the worst drop's marked."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 3.2), layout="constrained")
    ax = fig.subplots()
    t = [s.time_s for s in r.steps]
    ax.plot(t, [np.nan if s.figures.get("precision") is None else s.figures["precision"]
                for s in r.steps], ".-", label="precision of the published map")
    ax.axvline(r.k_time, color="k", lw=0.8, ls=":", label=f"drift starts (scan {r.k})")
    if r.drop_start is not None:
        ax.axvline(r.steps[r.drop_start].time_s, color="#ee6677", lw=1.2,
                   label="worst drop starts")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("time since the recording's start [s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    fig.suptitle(f"{r.log} as a recording of published maps", fontsize=10)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    return buffer.getvalue()


def _first_fall(r: Recorded) -> str:
    """How the first drifted map's figures moved from the map before it, in words."""
    before, first = r.steps[r.k_step - 1].figures, r.steps[r.k_step].figures
    return (f"From step {r.k_step - 1} to step {r.k_step} the mean precision went from "
            f"{before['precision']:.3f} to {first['precision']:.3f} (a drop starts where the "
            f"fall reaches {MIN_DROP:g}) and the wall precision at 0.1 m from "
            f"{before['wall_precision@0.1m']:.3f} to {first['wall_precision@0.1m']:.3f}.")


def section(data: Path, record: Record) -> Section:
    measured = [case.run(record) for case in cases(data)]
    text = ["## pcmapq track on a ROS recording of published maps", "",
            f"A CARMEN log made into a ROS 2 MCAP recording: every {EVERY} scans the map of the "
            f"scans so far as a `nav_msgs/OccupancyGrid` on `/map` ({RESOLUTION:g} m cells: "
            "endpoints occupied, the area the scans saw free), at the log's times, and every "
            "scan as a `sensor_msgs/LaserScan` on `/scan`; the poses after the middle scan "
            f"carry a {100 * LEVEL:g} % gain error, as in the section above. "
            "`pcmapq track RUN.mcap LOG` scores every map published against the map of the "
            "log's corrected poses.", ""]
    files = {}
    for r in measured:
        stem = r.log.split("-")[0]
        drop = ("no drop" if r.drop_start is None else
                f"the worst drop starts at step {r.drop_start}, "
                f"{r.steps[r.drop_start].time_s:.1f} s")
        text += [f"### {r.log} ({len(r.steps)} maps published, {r.scans} scans; "
                 f"{r.seconds:.0f} s)", "",
                 f"![{r.log}](img/recording-{stem}.png)", "",
                 f"The recording holds {r.bag_bytes / 1e6:.1f} MB; its `/scan` messages read "
                 f"back as {r.laser_points:,} laser points. The drift starts at scan {r.k} "
                 f"({r.k_time:.1f} s); the first map holding a drifted scan is step "
                 f"{r.k_step} ({r.steps[r.k_step].time_s:.1f} s); {drop}. "
                 f"{_first_fall(r)}", ""]
        files[f"img/recording-{stem}.png"] = picture(r)
    return Section("\n".join(text), files)
