"""Quality over time (``pcmapq track``): a SLAM run's map scored as it grows.

:func:`track_run` scores the map of the scans so far every N scans (or D metres) against a
truth prepared once, and :func:`write_track` writes ``track.csv``, ``track.json``,
``track.png`` and ``track.html`` (the curves, and the vectorial map at the worst drop with the
robot's path). Modules: :mod:`~pcmapq.track.runs` (the scans and poses of a run, and its growing
map), :mod:`~pcmapq.track.steps` (when to score), :mod:`~pcmapq.track.timeline` (the scoring
loop), :mod:`~pcmapq.track.drop` (the worst drop), :mod:`~pcmapq.track.outputs` (the
files)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from pcmapq.core.words import count, plural
from pcmapq.evaluation.inputs import TRUTH_CROP, load_input
from pcmapq.evaluation.truth import PreparedTruth, prepare_truth
from pcmapq.io.writers import OutputSet, write_atomic
from pcmapq.results.result import Result
from pcmapq.settings import Settings
from pcmapq.track.drop import Drop, worst_drop
from pcmapq.track.outputs import step_rows, track_csv, track_json
from pcmapq.track.recording import Recording, grid_result, score_grids
from pcmapq.track.runs import Run, open_run, planar_of, planar_poses
from pcmapq.track.steps import step_ends, travelled
from pcmapq.track.timeline import (
    FEATURE_THREADS,
    PoseOptions,
    Step,
    plane_points,
    result_at,
    track,
)

__all__ = ["PoseOptions", "Recording", "Step", "Tracked", "open_run", "planar_of",
           "planar_poses", "step_ends", "track", "track_recording", "track_run", "travelled",
           "worst_drop", "write_track"]

#: The files a tracked run writes into its folder.
FILES = ("track.csv", "track.json", "track.png", "track.html")


@dataclass(frozen=True)
class Tracked:
    """A tracked run: its steps, the worst drop (None with fewer than two scored steps), the
    step shown in the report (its index; ``asked``: chosen by the caller) with its full result
    and the robot's path in the truth frame up to it (None when that step was not scored);
    ``reference``: the file of the reference poses, ``pose_options`` how they compare."""

    run: Run | Recording
    truth: PreparedTruth
    settings: Settings
    steps: list[Step]
    drop: Drop | None
    shown: int
    result: Result | None
    path_xy: np.ndarray | None
    asked: bool = False
    reference: Path | None = None
    pose_options: PoseOptions = PoseOptions()

    @cached_property
    def rows(self) -> list[dict[str, object]]:
        """The steps as the rows of ``track.csv`` and ``track.json``
        (:func:`~pcmapq.track.outputs.step_rows`), built once."""
        return step_rows(self.steps)


def track_run(run: Run, truth_path: Path, settings: Settings, ends: np.ndarray, *,
              reference: np.ndarray | None = None, pose_options: PoseOptions = PoseOptions(),  # noqa: B008 (frozen)
              reference_path: Path | None = None, show: int | None = None,
              progress: Callable[[str], None] = lambda s: None,
              tick: Callable[[int], None] = lambda done: None,
              memory_limit: int | None = None) -> Tracked:
    """Score ``run`` after each of ``ends`` scans against the truth at ``truth_path`` (the
    no-reference figures are left out: they do not change with the map's pose); ``reference``:
    reference poses (K, 4, 4) from ``reference_path``; ``show``: the step the report shows
    (default: where the worst drop starts, else the last). As many steps are scored at once
    as fit in ``memory_limit`` bytes (None: :func:`pcmapq.core.memory.default_limit`), at most
    three; InputError (one line) when not even one does. The results kept for the report
    (at most :data:`~pcmapq.track.timeline.KEEP_BYTES`) are not counted."""
    settings = replace(settings, noref=replace(settings.noref, enabled=False))
    progress("preparing the truth")
    truth = prepare_truth(load_input(truth_path, settings.truth, TRUTH_CROP,
                                     memory_limit=memory_limit), settings, memory_limit,
                          maps=tuple(range(FEATURE_THREADS + 1, 0, -1)))
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
    return Tracked(run, truth, settings, steps, drop, shown, result, path, show is not None,
                   reference_path if reference is not None else None, pose_options)


def track_recording(recording: Recording, truth_path: Path, settings: Settings, *,
                    show: int | None = None, progress: Callable[[str], None] = lambda s: None,
                    memory_limit: int | None = None) -> Tracked:
    """Score every OccupancyGrid of a recording (:mod:`~pcmapq.track.recording`) against the
    truth at ``truth_path``, as :func:`track_run` scores a growing map: the worst drop, the
    step shown (``show``, default where the worst drop starts, else the last) with its full
    result; no robot path."""
    settings = replace(settings, noref=replace(settings.noref, enabled=False))
    progress("preparing the truth")
    truth = prepare_truth(load_input(truth_path, settings.truth, TRUTH_CROP,
                                     memory_limit=memory_limit), settings, memory_limit)
    steps = score_grids(recording, truth, settings, progress)
    drop = worst_drop(steps)
    shown = show if show is not None else drop.start if drop is not None else len(steps) - 1
    shown = min(max(shown, 0), len(steps) - 1)
    result = None
    if steps[shown].scored:
        progress("drawing the step shown")
        result = grid_result(recording, truth, settings, steps[shown])
    return Tracked(recording, truth, settings, steps, drop, shown, result,
                   None if result is None else np.zeros((0, 2)), show is not None)


def inputs_of(tracked: Tracked, every: dict) -> dict[str, str]:
    """What a tracked run scored, in words, by name: the run, its poses, the truth, the
    reference poses and how they compare, the step rule."""
    run, options = tracked.run, tracked.pose_options
    words = {"run": str(run.path), "poses": run.poses_source,
             "truth": str(tracked.truth.source.path)}
    if tracked.reference is not None:
        how = {(True, True): "aligned with scale (Sim(3) Umeyama)",
               (True, False): "aligned (SE(3) Umeyama)",
               (False, True): "scale corrected, not aligned",
               (False, False): "not aligned"}[options.align, options.correct_scale]
        words["reference poses"] = (f"{tracked.reference}; {how}, RPE over {options.delta} "
                                    f"{plural(options.delta, 'scan')}")
    words["steps"] = (f"every {count(every['every_scans'], 'scan')}" if every.get("every_scans")
                      else f"every {every['every_m']:g} m travelled" if every.get("every_m")
                      else f"every map published, at most one per {every['every_s']:g} s"
                      if every.get("every_s") else "every map published") + ", and the last"
    return words


def write_track(tracked: Tracked, out: Path, every: dict, command: str | None) -> list[Path]:
    """Write the run's files into ``out`` (made if missing), all or none; the paths."""
    from pcmapq.report.plot import png_bytes
    from pcmapq.report.timeline import timeline_figure, timeline_html

    rows = tracked.rows
    drop = None if tracked.drop is None else asdict(tracked.drop)
    inputs = inputs_of(tracked, every)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / name for name in FILES]
    with OutputSet() as outputs:
        write_atomic(paths[0], track_csv(rows), outputs)
        write_atomic(paths[1], track_json(
            rows, tracked.drop, run=tracked.run.path, poses=tracked.run.poses_source,
            truth=tracked.truth.source.path, reference=tracked.reference,
            pose_options=asdict(tracked.pose_options), settings=tracked.settings.to_dict(),
            every=every, command=command), outputs)
        title = f"{tracked.run.path.name} against {tracked.truth.source.path.name}"
        curves = png_bytes(timeline_figure(rows, drop, title))
        write_atomic(paths[2], curves, outputs)
        write_atomic(paths[3], timeline_html(rows, drop, tracked.shown, tracked.result,
                                             tracked.path_xy, inputs=inputs, command=command,
                                             asked=tracked.asked, curves=curves), outputs)
        outputs.commit()
    return paths
