"""evaluate(): the method in one screen. load -> align -> raster -> features -> match -> score."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from pcmapq.align import align
from pcmapq.config import Settings
from pcmapq.errors import EvaluationError, InputError
from pcmapq.features import detect
from pcmapq.grid import MetricGrid
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.match import match
from pcmapq.raster.draw import OCCUPIED, points_to_grid, warp_state
from pcmapq.raster.slice import wall_band
from pcmapq.result import DetectorResult, Result

Progress = Callable[[str], None]


def plan_points(source: OccupancyMap | PointMap, settings: Settings) -> np.ndarray:
    """The 2D structure of an input, (N, 2) metres in its own frame: occupied cell centres of an
    image, the wall band of a 3D cloud, or a 2D cloud as it is."""
    if isinstance(source, OccupancyMap):
        xy = source.grid.cell_centres(source.state == OCCUPIED)
    elif source.is_3d:
        try:
            xy = wall_band(source.points, settings.band_low, settings.band_high)
        except ValueError as err:
            raise InputError(f"{source.path}: {err}") from None
    else:
        xy = source.points[:, :2]
    if len(xy) == 0:
        raise InputError(f"{source.path}: no occupied cells or wall points")
    return xy


def truth_raster(truth: OccupancyMap | PointMap, truth_xy: np.ndarray,
                 settings: Settings) -> tuple[MetricGrid, np.ndarray]:
    """The truth's grid and its occupied cells. An image keeps its own grid; a cloud gets an
    axis-aligned grid around its points at ``truth_resolution`` (or ``cloud_resolution``)."""
    if isinstance(truth, OccupancyMap):
        return truth.grid, truth.state == OCCUPIED
    grid = MetricGrid.covering(truth_xy, settings.truth_resolution or settings.cloud_resolution)
    return grid, points_to_grid(truth_xy, grid, settings.min_hits)


def map_raster(source: OccupancyMap | PointMap, map_xy: np.ndarray, transform, grid: MetricGrid,
               settings: Settings) -> np.ndarray:
    """The aligned map drawn into the truth's grid: occupied cells, bool."""
    if isinstance(source, OccupancyMap):
        return warp_state(source.state, source.grid, transform, grid) == OCCUPIED
    return points_to_grid(transform.apply(map_xy), grid, settings.min_hits)


def evaluate(map_path: str | Path, truth_path: str | Path, settings: Settings = Settings(),
             progress: Progress = lambda step: None) -> Result:
    """Score the map at ``map_path`` against the truth at ``truth_path``."""
    progress("loading")
    source = load_map(map_path, settings.map_resolution)
    truth = load_map(truth_path, settings.truth_resolution)
    map_xy, truth_xy = plan_points(source, settings), plan_points(truth, settings)

    progress("aligning")
    alignment = align(map_xy, truth_xy, init=settings.init, refine=settings.align,
                      tolerance=settings.fit_tolerance)
    if alignment.fitness < settings.min_fitness and not settings.force:
        raise EvaluationError(
            f"{map_path}: does not match {truth_path}: only {alignment.fitness:.0%} of the map "
            f"lies within {settings.fit_tolerance} m of the truth after alignment (minimum "
            f"{settings.min_fitness:.0%}); a map of another place? --force evaluates anyway")

    progress("rasterising")
    grid, truth_occ = truth_raster(truth, truth_xy, settings)
    map_occ = map_raster(source, map_xy, alignment.transform, grid, settings)

    detectors = {}
    for name in settings.detectors:
        progress(f"detecting {name}")
        truth_f, map_f = detect(name, truth_occ, grid), detect(name, map_occ, grid)
        detectors[name] = DetectorResult(truth_f, map_f,
                                         match(name, truth_f, map_f, settings.threshold))
    return Result(map_path=Path(map_path), map_kind=source.kind, truth_path=Path(truth_path),
                  truth_kind=truth.kind, grid=grid, alignment=alignment, threshold=settings.threshold,
                  detectors=detectors, truth_occupied=truth_occ, map_occupied=map_occ)
