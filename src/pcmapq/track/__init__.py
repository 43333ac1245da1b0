"""Quality over time (``pcmapq track``): a SLAM run's map scored as it grows.

:func:`track_run` scores the map of the scans so far every N scans (or D metres) against a
truth prepared once, and :func:`write_track` writes ``track.csv``, ``track.json``,
``track.png`` and ``track.html`` (the curves, and the vectorial map at the worst drop with the
robot's path). Modules: :mod:`~pcmapq.track.runs` (the scans and poses of a run, and its growing
map), :mod:`~pcmapq.track.steps` (when to score), :mod:`~pcmapq.track.timeline` (the scoring
loop and the worst drop), :mod:`~pcmapq.track.outputs` (the files)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from pcmapq.config import Settings
from pcmapq.io.writers import OutputSet, write_atomic
from pcmapq.pipeline import PreparedTruth, prepare_truth
from pcmapq.plan import TRUTH_CROP, load_input
from pcmapq.result import Result
from pcmapq.track.outputs import step_rows, track_csv, track_json
from pcmapq.track.runs import Run, open_run, planar_of, planar_poses
from pcmapq.track.steps import step_ends, travelled
from pcmapq.track.timeline import (
    Drop,
    PoseOptions,
    Step,
    plane_points,
    result_at,
    track,
    worst_drop,
)

__all__ = ["PoseOptions", "Step", "Tracked", "open_run", "planar_of", "planar_poses",
           "step_ends", "track", "track_run", "travelled", "worst_drop", "write_track"]

#: The files a tracked run writes into its folder.
FILES = ("track.csv", "track.json", "track.png", "track.html")


@dataclass(frozen=True)
class Tracked:
    """A tracked run: its steps, the worst drop (None with fewer than two scored steps), the
    step shown in the report (its index) with its full result and the robot's path in the
    truth frame up to it (None when that step was not scored)."""

    run: Run
    truth: PreparedTruth
    settings: Settings
    steps: list[Step]
    drop: Drop | None
    shown: int
    result: Result | None
    path_xy: np.ndarray | None


def track_run(run: Run, truth_path: Path, settings: Settings, ends: np.ndarray, *,
              reference: np.ndarray | None = None, pose_options: PoseOptions = PoseOptions(),  # noqa: B008 (frozen)
              show: int | None = None, progress: Callable[[str], None] = lambda s: None,
              tick: Callable[[int], None] = lambda done: None) -> Tracked:
    """Score ``run`` after each of ``ends`` scans against the truth at ``truth_path`` (the
    no-reference figures are left out: they do not change with the map's pose); ``show``: the
    step the report shows (default: where the worst drop starts, else the last)."""
    settings = replace(settings, noref=replace(settings.noref, enabled=False))
    progress("preparing the truth")
    truth = prepare_truth(load_input(truth_path, settings.truth, TRUTH_CROP), settings)
    progress("scoring the steps")
    steps = track(run, truth, settings, ends, reference, pose_options, tick)
    drop = worst_drop(steps)
    shown = show if show is not None else drop.start if drop is not None else len(steps) - 1
    shown = min(max(shown, 0), len(steps) - 1)
    result = path = None
    if steps[shown].scored:
        progress("drawing the step shown")
        result = result_at(run, truth, settings, steps[shown])
        path = plane_points(run.poses[:steps[shown].scans, :3, 3], result.frames)
    return Tracked(run, truth, settings, steps, drop, shown, result, path)


def write_track(tracked: Tracked, out: Path, every: dict, command: str | None) -> list[Path]:
    """Write the run's files into ``out`` (made if missing), all or none; the paths."""
    from pcmapq.report.plot import png_bytes
    from pcmapq.report.timeline import timeline_figure, timeline_html

    rows = step_rows(tracked.steps)
    drop = None if tracked.drop is None else asdict(tracked.drop)
    run, truth = str(tracked.run.path), str(tracked.truth.source.path)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / name for name in FILES]
    with OutputSet() as outputs:
        write_atomic(paths[0], track_csv(rows), outputs)
        write_atomic(paths[1], track_json(rows, tracked.drop, run=tracked.run.path,
                                          truth=tracked.truth.source.path,
                                          settings=tracked.settings.to_dict(), every=every,
                                          command=command), outputs)
        write_atomic(paths[2], png_bytes(timeline_figure(rows, drop)), outputs)
        write_atomic(paths[3], timeline_html(rows, drop, tracked.shown, tracked.result,
                                             tracked.path_xy, run=run, truth=truth,
                                             command=command), outputs)
        outputs.commit()
    return paths
