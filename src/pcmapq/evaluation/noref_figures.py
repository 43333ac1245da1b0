"""The no-reference figures of one loaded input, map or truth: what ``pcmapq inspect`` reports
and ``pcmapq eval`` reports for both sides under ``"noref"``. A 3D cloud gets MME, MPV and MOM
(:mod:`pcmapq.metrics.inspection`, as map-metrics defines them); an image or a 2D cloud gets the
occupancy figures of :mod:`pcmapq.metrics.noref2d`. docs/metrics.md says what each can tell.
"""

from __future__ import annotations

from dataclasses import asdict, replace
from typing import Any

import numpy as np

from pcmapq.core.voxels import voxel_centroids
from pcmapq.evaluation.inputs import truth_raster
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.metrics.inspection import noref_figures
from pcmapq.metrics.noref2d import grid_scores
from pcmapq.raster.draw import OCCUPIED, UNKNOWN
from pcmapq.settings import NoRefConfig, Settings


def input_figures(source: OccupancyMap | PointMap, config: NoRefConfig = NoRefConfig(),
                  orth_subset: list[np.ndarray] | None = None, scale: float = 1.0,
                  corners: int | None = None) -> dict[str, Any]:
    """``{"cloud": 3D figures or None, "grid": 2D figures or None}`` of one input, in metres
    times ``scale`` (the map's estimated scale under ``--scale auto``; 1: its own units).
    ``orth_subset``: MOM's planes in the input's frame (None: extracted from the cloud, after
    the voxel reduction of ``config.voxel``). ``corners``: an image's Harris corners when
    already found (see :func:`pcmapq.metrics.noref2d.grid_scores`)."""
    if isinstance(source, PointMap) and source.is_3d:
        points = np.asarray(source.points, dtype=np.float64) * scale
        if config.voxel > 0:
            points = voxel_centroids(points, config.voxel)
        planes = None if orth_subset is None else [p * scale for p in orth_subset]
        figures = noref_figures(points, config.radius, config.min_knn, config.max_nn, planes,
                                max_ward=config.max_ward)
        return {"cloud": {**figures, "voxel_m": config.voxel}, "grid": None}
    return {"cloud": None, "grid": occupancy_figures(source, scale, corners)}


def occupancy_figures(source: OccupancyMap | PointMap, scale: float = 1.0,
                      corners: int | None = None) -> dict[str, Any]:
    """The 2D figures of an image, or of a 2D cloud drawn as ``eval`` draws a cloud truth
    (:func:`pcmapq.evaluation.inputs.truth_raster`, default settings; a cloud has no free cells: its
    occupied/free ratio and enclosed areas are None). Cells ``scale`` times their size."""
    if isinstance(source, OccupancyMap):
        state, grid = source.state, source.grid
    else:
        grid, occupied = truth_raster(source, source.points[:, :2] * scale, Settings())
        state = np.where(occupied, OCCUPIED, UNKNOWN).astype(np.int8)
    if isinstance(source, OccupancyMap) and scale != 1.0:
        grid = replace(grid, resolution=grid.resolution * scale)
    figures = asdict(grid_scores(state, grid, corners=corners))
    figures["resolution_m"] = grid.resolution
    if isinstance(source, PointMap):
        figures.update(free_cells=None, occupied_free_ratio=None, enclosed_areas=None,
                       enclosed_area_m2=None)
    return figures
