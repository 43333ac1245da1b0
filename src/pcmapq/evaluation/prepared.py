"""A truth prepared once, and many maps scored against it (``pcmapq track``'s steps): the
results of :func:`pcmapq.evaluation.pipeline.score` without the truth's work for each map."""

from __future__ import annotations

from pcmapq.align.planar import RigidTarget
from pcmapq.core import memory
from pcmapq.evaluation.inputs import MAP_CROP, TRUTH_CROP, plan_points, truth_cells, truth_grid
from pcmapq.evaluation.pipeline import (
    MapSide,
    PreparedTruth,
    Progress,
    assemble,
    map_footprint_rule,
    needed_memory,
    place_map,
    with_features,
)
from pcmapq.features import SideBySide
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.extent import check_span, hint
from pcmapq.metrics.distances import nearest_distance
from pcmapq.results.result import Result
from pcmapq.settings import Settings


def prepare_truth(truth: OccupancyMap | PointMap, settings: Settings,
                  memory_limit: int | None = None,
                  maps: tuple[int, ...] = (1,)) -> PreparedTruth:
    """Everything of the truth that does not depend on the map: plan points, raster, features
    (on two threads) and distance field; see :class:`~pcmapq.evaluation.pipeline.PreparedTruth`.

    maps: how many maps the caller would score on its grid at once, most wanted first; the
    first whose estimated memory fits in ``memory_limit`` bytes (None: the default) is kept as
    ``PreparedTruth.maps``; InputError (one line) when none fits."""
    check_span(truth, TRUTH_CROP)
    truth_xy, level = plan_points(truth, settings)
    grid = truth_grid(truth, truth_xy, settings)
    need = {n: needed_memory((truth,), grid, n) for n in maps}
    limit = memory.default_limit() if memory_limit is None else memory_limit
    fits = [n for n in maps if need[n] <= limit]
    least = min(maps)
    memory.guard(need[fits[0] if fits else least], memory_limit,
                 f"{truth.path} with {least} map{'s' * (least > 1)} scored on its grid",
                 lambda: hint(truth, TRUTH_CROP, grid.resolution))
    occupied = truth_cells(truth, truth_xy, grid, settings)
    sides = SideBySide(settings.matching.detectors, settings.matching.params)
    option = settings.alignment
    aligner = (RigidTarget(truth_xy, option.params) if option.enabled and not option.scale
               else None)
    return PreparedTruth(truth, truth_xy, level, grid, occupied,
                         sides.features(occupied, grid, threads=2),
                         nearest_distance(occupied, grid), aligner,
                         fits[0] if fits else least)


def score_prepared(source: OccupancyMap | PointMap, prepared: PreparedTruth,
                   settings: Settings, progress: Progress = lambda step: None) -> Result:
    """:func:`~pcmapq.evaluation.pipeline.score` against a truth prepared once
    (:func:`prepare_truth`) with the same ``settings``: the same result, without the truth's
    work."""
    return finish_prepared(source, place_prepared(source, prepared, settings, progress),
                           prepared, settings, progress)


def place_prepared(source: OccupancyMap | PointMap, prepared: PreparedTruth,
                   settings: Settings, progress: Progress = lambda step: None) -> MapSide:
    """The first half of :func:`score_prepared`: ``source`` aligned, drawn and checked
    (:func:`~pcmapq.evaluation.pipeline.place_map`), without features."""
    check_span(source, MAP_CROP)
    return place_map(source, prepared.source, prepared.xy, prepared.grid, prepared.occupied,
                     settings, map_footprint_rule(source, settings), progress,
                     prepared.aligner)


def finish_prepared(source: OccupancyMap | PointMap, side: MapSide, prepared: PreparedTruth,
                    settings: Settings, progress: Progress = lambda step: None) -> Result:
    """The second half of :func:`score_prepared`: the features of ``side`` (from
    :func:`place_prepared`) matched against the prepared truth's, and the result."""
    sides = SideBySide(settings.matching.detectors, settings.matching.params)
    return assemble(source, with_features(side, prepared.grid, sides, progress), prepared,
                    settings, map_footprint_rule(source, settings), progress)
