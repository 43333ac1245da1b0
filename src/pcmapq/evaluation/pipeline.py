"""evaluate(): the method in one screen. load -> prepare the truth -> :func:`evaluate_prepared`:
check the map against the settings, place it (align, raster, same-place verdict), score it
(features, match, distances). Every command scores a map through :func:`evaluate_prepared`;
``pcmapq track`` calls its two halves (:func:`start_evaluation`, :func:`finish_evaluation`) on
two threads, placing the next step's map while this one's features are found."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from pcmapq.evaluation.inputs import load_pair
from pcmapq.evaluation.noref_figures import EarlyFigures
from pcmapq.evaluation.placing import (
    Placed,
    Progress,
    check_footprint_rule,
    check_init_3d,
    check_stretch,
    place,
)
from pcmapq.evaluation.scoring import score
from pcmapq.evaluation.truth import PreparedTruth, prepare_truth
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.digest import sha256_file
from pcmapq.results.result import Result
from pcmapq.settings import Settings


def evaluate(map_path: str | Path | PointMap, truth_path: str | Path,
             settings: Settings | None = None, progress: Progress = lambda step: None,
             memory_limit: int | None = None, truth_sha256: str | None = None) -> Result:
    """Score the map at ``map_path`` (or a map already built, e.g. from scans) against the
    truth at ``truth_path``; stop (InputError) when the run would need more than
    ``memory_limit`` bytes (None: :func:`pcmapq.core.memory.default_limit`).
    ``truth_sha256``: the truth file's SHA-256 when the caller has it (a batch row's key),
    else read here. The truth's features, and the 3D clouds' no-reference figures, are found on
    threads of their own while the map is placed."""
    settings = Settings() if settings is None else settings
    progress("loading")
    source, truth = load_pair(map_path, truth_path, settings, memory_limit)
    check_footprint_rule(source, settings)  # before the truth is prepared: a refusal costs nothing
    check_init_3d(source, truth, settings)
    check_stretch(source, settings)
    prepared = prepare_truth(truth, settings, memory_limit, maps=(0,), loaded=(source,),
                             background=True)
    try:
        result = evaluate_prepared(source, prepared, settings, progress)
    except BaseException:
        prepared.cancel()
        raise
    return replace(result, truth_sha256=truth_sha256 or sha256_file(truth_path))


def evaluate_prepared(source: OccupancyMap | PointMap, prepared: PreparedTruth,
                      settings: Settings, progress: Progress = lambda step: None) -> Result:
    """Score a loaded map against a prepared truth: the footprint rule checked
    (SettingsRefused), the no-reference figures of the 3D clouds and of an image map started on
    a thread of their own when ``settings.noref.enabled``, the map placed
    (:func:`~pcmapq.evaluation.placing.place`) and scored
    (:func:`~pcmapq.evaluation.scoring.score`). The result has no ``truth_sha256``."""
    return finish_evaluation(start_evaluation(source, prepared, settings, progress), progress)


@dataclass(frozen=True)
class Underway:
    """An evaluation half done (:func:`start_evaluation`): its map ``placed`` on the
    ``prepared`` truth with ``settings``, its ``early`` no-reference figures being found."""

    placed: Placed
    prepared: PreparedTruth
    settings: Settings
    early: EarlyFigures


def start_evaluation(source: OccupancyMap | PointMap, prepared: PreparedTruth,
                     settings: Settings, progress: Progress = lambda step: None) -> Underway:
    """The first half of :func:`evaluate_prepared`: the rule checked, the early figures
    started, the map placed (its errors raised, the figures' thread stopped)."""
    check_footprint_rule(source, settings)
    check_stretch(source, settings)
    early = EarlyFigures({"map": source, "truth": prepared.source}, settings)
    try:
        placed = place(source, prepared, settings, progress, early.walls_found)
    except BaseException:
        early.cancel()
        raise
    return Underway(placed, prepared, settings, early)


def finish_evaluation(underway: Underway, progress: Progress = lambda step: None) -> Result:
    """The second half of :func:`evaluate_prepared`: the placed map scored with the settings it
    was placed with (its errors raised, the figures' thread stopped)."""
    try:
        return score(underway.placed, underway.prepared, underway.settings, progress,
                     underway.early)
    except BaseException:
        underway.early.cancel()
        raise
