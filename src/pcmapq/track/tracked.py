"""A run tracked against a truth prepared once: :func:`track_run` scores a growing map at its
steps, :func:`track_recording` the maps a recording published; either gives a
:class:`Tracked` (its steps, the worst drop, the step the report shows with its full result)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from pcmapq.evaluation.inputs import TRUTH_CROP, load_input
from pcmapq.evaluation.truth import PreparedTruth, prepare_truth
from pcmapq.results.result import Result
from pcmapq.settings import Settings
from pcmapq.track.drop import Drop, worst_drop
from pcmapq.track.outputs import step_rows
from pcmapq.track.recording import Recording, grid_result, score_grids
from pcmapq.track.runs import Run
from pcmapq.track.timeline import (
    FEATURE_THREADS,
    PoseOptions,
    Step,
    plane_points,
    result_at,
    track,
)


@dataclass(frozen=True)
class Tracked:
    """A tracked run: its steps, the worst drop (None with fewer than two scored steps), the
    step shown in the report (its index; ``asked``: chosen by the caller) with its full result
    and the robot's path in the truth frame up to it (None when that step was not scored);
    ``reference``: the file of the reference poses, ``pose_options`` how they compare;
    ``every``: the rule of its steps as ``track.json`` names it (empty when not given)."""

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
    every: dict = field(default_factory=dict)

    @cached_property
    def rows(self) -> list[dict[str, object]]:
        """The steps as the rows of ``track.csv`` and ``track.json``
        (:func:`~pcmapq.track.outputs.step_rows`), built once."""
        return step_rows(self.steps)


def track_settings(settings: Settings) -> Settings:
    """The settings each step is scored with: the no-reference figures left out, as
    docs/commands/track.md says (they do not change with the map's pose)."""
    return replace(settings, noref=replace(settings.noref, enabled=False))


def track_run(run: Run, truth_path: Path, settings: Settings, ends: np.ndarray, *,
              reference: np.ndarray | None = None, pose_options: PoseOptions = PoseOptions(),  # noqa: B008 (frozen)
              reference_path: Path | None = None, show: int | None = None,
              progress: Callable[[str], None] = lambda s: None,
              tick: Callable[[int], None] = lambda done: None,
              memory_limit: int | None = None) -> Tracked:
    """Score ``run`` after each of ``ends`` scans against the truth at ``truth_path``
    (:func:`track_settings`); ``reference``: reference poses (K, 4, 4) from
    ``reference_path``; ``show``: the step the report shows (default: where the worst drop
    starts, else the last). As many steps are scored at once as fit in ``memory_limit`` bytes
    (None: :func:`pcmapq.core.memory.default_limit`), at most three; InputError (one line)
    when not even one does. The results kept for the report (at most
    :data:`~pcmapq.track.timeline.KEEP_BYTES`) are not counted."""
    settings = track_settings(settings)
    truth = _prepared(truth_path, settings, memory_limit, progress,
                      maps=tuple(range(FEATURE_THREADS + 1, 0, -1)))
    progress("scoring the steps")
    steps = track(run, truth, settings, ends, reference, pose_options, tick)
    drop = worst_drop(steps)
    shown = _shown(show, drop, steps)
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
    settings = track_settings(settings)
    truth = _prepared(truth_path, settings, memory_limit, progress)
    steps = score_grids(recording, truth, settings, progress)
    drop = worst_drop(steps)
    shown = _shown(show, drop, steps)
    result = None
    if steps[shown].scored:
        progress("drawing the step shown")
        result = grid_result(recording, truth, settings, steps[shown])
    return Tracked(recording, truth, settings, steps, drop, shown, result,
                   None if result is None else np.zeros((0, 2)), show is not None)


def _prepared(truth_path: Path, settings: Settings, memory_limit: int | None,
              progress: Callable[[str], None], maps: tuple[int, ...] = (1,)) -> PreparedTruth:
    """The truth at ``truth_path`` loaded and prepared once for every step
    (:func:`~pcmapq.evaluation.truth.prepare_truth`, ``maps`` scored on its grid at once)."""
    progress("preparing the truth")
    return prepare_truth(load_input(truth_path, settings.truth, TRUTH_CROP,
                                    memory_limit=memory_limit), settings, memory_limit,
                         maps=maps)


def _shown(show: int | None, drop: Drop | None, steps: list[Step]) -> int:
    """The step the report shows: ``show`` (kept within the steps), else where the worst drop
    starts, else the last."""
    shown = show if show is not None else drop.start if drop is not None else len(steps) - 1
    return min(max(shown, 0), len(steps) - 1)
