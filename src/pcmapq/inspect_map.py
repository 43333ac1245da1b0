"""``pcmapq inspect``: how good a map is without a ground truth. A 3D cloud (or scans placed at
their poses) gets MME, MPV and MOM (:mod:`pcmapq.metrics.noref`, as map-metrics defines them); a
2D map gets the occupancy figures of :mod:`pcmapq.metrics.noref2d`. docs/metrics.md says what
each figure can and cannot tell.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq import __version__
from pcmapq.config import Settings
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.metrics.inspection import noref_figures
from pcmapq.metrics.noref import LIDAR_RADIUS, MAX_NN, MIN_KNN
from pcmapq.metrics.noref2d import grid_scores
from pcmapq.pipeline import truth_raster
from pcmapq.raster.draw import OCCUPIED, UNKNOWN


@dataclass(frozen=True)
class NoRefConfig:
    """The neighbourhood of the 3D figures: ``radius`` metres (1.0 for LiDAR maps, 0.2 for depth
    cameras), more than ``min_knn`` neighbours for a point to count, ``max_nn`` nearest
    neighbours for the normals that pick MOM's orthogonal planes."""

    radius: float = LIDAR_RADIUS
    min_knn: int = MIN_KNN
    max_nn: int = MAX_NN


def inspect_map(source: OccupancyMap | PointMap, config: NoRefConfig = NoRefConfig(),
                orth_subset: Sequence[np.ndarray] | None = None,
                command: str = "") -> dict[str, Any]:
    """The no-reference figures of one map as a JSON-ready record: ``noref`` (3D clouds: MME
    nats, MPV and MOM m^2) or ``grid`` (images and 2D clouds), the other None.
    ``orth_subset``: MOM's planes in the map's frame (None: extracted from the map)."""
    record: dict[str, Any] = {
        "pcmapq": {"version": __version__, "command": command},
        "map": {"path": str(source.path), "kind": source.kind},
        "noref": None, "grid": None,
    }
    if isinstance(source, PointMap) and source.is_3d:
        points = np.asarray(source.points, dtype=np.float64)
        record["noref"] = noref_figures(points, config.radius, config.min_knn, config.max_nn,
                                        orth_subset)
        return record
    record["grid"] = occupancy_figures(source)
    return record


def occupancy_figures(source: OccupancyMap | PointMap) -> dict[str, Any]:
    """The 2D figures of an image, or of a 2D cloud drawn as ``eval`` draws a cloud truth
    (:func:`pcmapq.pipeline.truth_raster`; a cloud has no free cells: its occupied/free ratio
    and enclosed areas are None)."""
    if isinstance(source, OccupancyMap):
        state, grid = source.state, source.grid
    else:
        grid, occupied = truth_raster(source, source.points[:, :2], Settings())
        state = np.where(occupied, OCCUPIED, UNKNOWN).astype(np.int8)
    figures = asdict(grid_scores(state, grid))
    figures["resolution_m"] = grid.resolution
    if isinstance(source, PointMap):
        figures.update(free_cells=None, occupied_free_ratio=None, enclosed_areas=None,
                       enclosed_area_m2=None)
    return figures


def to_json(record: dict[str, Any]) -> str:
    """The record as strict JSON (no NaN or infinity), as ``eval --json`` writes."""
    return json.dumps(record, indent=2, allow_nan=False) + "\n"


def summary_lines(record: dict[str, Any]) -> list[str]:
    """The record in a few labelled lines for the terminal, units in each."""
    lines = [f"map       {Path(record['map']['path']).name}, {record['map']['kind']}"]
    noref, grid = record["noref"], record["grid"]
    if noref is not None:
        near = f"within {noref['radius_m']:g} m, more than {noref['min_knn']} neighbours"
        lines += [f"points    {noref['points']:,} ({noref['mpv_points']:,} with neighbours "
                  f"{near})",
                  f"MME       {_num(noref['mme'])} nats (lower: crisper)",
                  f"MPV       {_num(noref['mpv'])} m² (lower: thinner surfaces)",
                  f"MOM       {_num(noref['mom'])} m² "
                  + (f"({noref['mom_note']})" if noref["mom"] is None else
                     f"(orthogonal planes {noref['orth_subset']})")]
    if grid is not None:
        ratio = grid["occupied_free_ratio"]
        lines += [f"cells     {grid['occupied_cells']:,} occupied of {grid['resolution_m']:g} m"
                  + ("" if grid["free_cells"] is None else f", {grid['free_cells']:,} free"),
                  f"ratio     {_num(ratio)} occupied / free",
                  f"corners   {grid['corners']:,}",
                  "enclosed  " + ("n/a (a cloud has no free cells)"
                                  if grid["enclosed_areas"] is None else
                                  f"{grid['enclosed_areas']:,} areas, "
                                  f"{grid['enclosed_area_m2']:.2f} m²")]
    return lines


def _num(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.6g}"
