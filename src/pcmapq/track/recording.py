"""Quality over time from a recording: every ``nav_msgs/OccupancyGrid`` a SLAM system
published (slam_toolbox's, Cartographer's ``/map``) scored against the truth, on the
recording's time axis (seconds from its start, as ``eval --at`` takes them). A grid the same
as the one before is not scored again; ``every_s`` thins the grids to one per that many
seconds (the last one always kept). Each grid's ICP
starts from the pose the grid before found (a global search when that start is refused), as
:func:`pcmapq.track.timeline.track` does for a growing map."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

from pcmapq.core.errors import EvaluationError, InputError, SettingsRefused
from pcmapq.evaluation.pipeline import evaluate_prepared, finish_evaluation
from pcmapq.evaluation.truth import PreparedTruth
from pcmapq.io.bag_grids import grids
from pcmapq.io.occupancy import OccupancyMap
from pcmapq.results.result import Result
from pcmapq.settings import Settings
from pcmapq.track.timeline import (
    KEEP_BYTES,
    Step,
    figures_of,
    next_start,
    place_step,
    settings_from,
)


@dataclass(frozen=True)
class Recording:
    """The run of a tracked recording: its file, and the topic its maps come from (None: the
    only OccupancyGrid topic, or ``/map``)."""

    path: Path
    topic: str | None
    every_s: float | None = None

    @property
    def poses_source(self) -> str:
        return f"none: the OccupancyGrid messages of {self.topic or 'its map topic'}"

    def grids(self, settings: Settings) -> Iterator[tuple[int, float, OccupancyMap]]:
        """(index among the distinct grids, seconds from the recording's start, grid) of the
        grids scored: one per ``every_s`` seconds at most, and the last."""
        pending = None
        last_kept = None
        for index, (t, grid) in enumerate(grids(self.path, self.topic,
                                               settings.map.thresholds)):
            if self.every_s is None or last_kept is None or t - last_kept >= self.every_s:
                last_kept, pending = t, None
                yield index, t, grid
            else:
                pending = (index, t, grid)
        if pending is not None:
            yield pending


def score_grids(recording: Recording, truth: PreparedTruth, settings: Settings,
                progress: Callable[[str], None] = lambda s: None) -> list[Step]:
    """Every grid of ``recording`` scored against the prepared truth, in time order
    (``scans``: the grid's number among the distinct ones, from 1; ``time_s`` since the
    recording's start;
    ``distance_m`` None: a recording's maps carry no path). Their full results are kept while
    they fit in :data:`~pcmapq.track.timeline.KEEP_BYTES`."""
    steps: list[Step] = []
    start = settings.alignment.init
    held: int | None = 0
    for index, t, grid in recording.grids(settings):
        progress(f"scoring the map published at {t:.1f} s")
        at = (len(steps), index + 1, t, None)
        try:
            underway, used = place_step(grid, truth, settings, start)
            result = finish_evaluation(underway)
        except SettingsRefused:
            raise  # no grid can follow them: the recording is refused, as eval's map is
        except (EvaluationError, InputError) as err:
            steps.append(Step(*at, {"slide_m": None, "local_offset_m": None}, str(err), start))
            continue
        if settings.alignment.enabled:
            start = next_start(underway.placed)
        if held is not None:
            held += result.map_occupied.nbytes + result.overlap.footprint.nbytes
            held = held if held <= KEEP_BYTES else None
        steps.append(Step(*at, {**figures_of(result), "slide_m": None, "local_offset_m": None},
                          "", used, result.frames, result if held is not None else None))
    if not steps:
        raise InputError(f"{recording.path}: the map topic holds no message")
    return steps if held is not None else [replace(s, result=None) for s in steps]


def grid_result(recording: Recording, truth: PreparedTruth, settings: Settings,
                step: Step) -> Result:
    """The full result of a scored step: kept, or scored again as it was (the same grid from
    the same start)."""
    if step.result is not None:
        return step.result
    grid = next(g for i, _, g in recording.grids(settings) if i + 1 == step.scans)
    return evaluate_prepared(grid, truth, settings_from(settings, step.start))
