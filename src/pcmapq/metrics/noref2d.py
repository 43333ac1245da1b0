"""No-reference figures of a 2D occupancy map, after Filatov et al. 2017 ("2D SLAM quality
evaluation methods"): the proportion of occupied to free cells, the number of corners and the
number of enclosed areas. A map built from drifted poses has blurred or doubled walls (more
occupied cells for the same free space), spurious corners where the copies cross, and small
pockets of free space walled in by them. All three only compare maps of the same place; lower
is better. Lengths in metres, areas in square metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from pcmapq.core.bounds import on_edge
from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.grid import MetricGrid
from pcmapq.features import detect
from pcmapq.features.harris import Params as HarrisParams

#: Enclosed free regions smaller than this are gaps inside a thick wall, not areas, m^2.
MIN_ENCLOSED_AREA = 0.05


@dataclass(frozen=True)
class GridScores:
    """The figures of one occupancy map.

    occupied_cells, free_cells: counts. occupied_free_ratio: occupied / free (None without free
    cells). corners: strong Harris corners of the walls (pcmapq's detector, its parameters in
    metres). enclosed_areas: free regions walled in on every side (touching neither an unknown
    cell nor the map's edge) of at least ``min_area_m2``; enclosed_area_m2: their total area.
    """

    occupied_cells: int
    free_cells: int
    occupied_free_ratio: float | None
    corners: int
    enclosed_areas: int
    enclosed_area_m2: float


def occupied_free(state: np.ndarray) -> tuple[int, int, float | None]:
    """Occupied and free cell counts of an int8 state raster, and their ratio."""
    occupied = int(np.count_nonzero(state == OCCUPIED))
    free = int(np.count_nonzero(state == FREE))
    return occupied, free, occupied / free if free else None


def corner_count(state: np.ndarray, grid: MetricGrid, params: HarrisParams | None = None) -> int:
    """Strong Harris corners of the occupied cells (pcmapq's detector, lengths in metres)."""
    return int(np.count_nonzero(detect("harris", state == OCCUPIED, grid, params).strong))


def enclosed_areas(state: np.ndarray, resolution: float,
                   min_area_m2: float = MIN_ENCLOSED_AREA) -> np.ndarray:
    """Areas (m^2, largest first) of the free regions enclosed by occupied cells: connected
    (4-neighbour: an 8-connected wall closes them) regions of non-occupied cells holding no
    unknown cell and not touching the map's edge, of at least ``min_area_m2``."""
    open_ = (state != OCCUPIED).astype(np.uint8)
    count, labels = cv2.connectedComponents(open_, connectivity=4)
    leaks = on_edge(labels, count)
    leaks[labels[state == UNKNOWN]] = True  # marked by indexing: no sort of the labels
    leaks[0] = True  # label 0: the occupied cells
    cells = np.bincount(labels.ravel(), minlength=count)
    areas = cells[~leaks] * resolution * resolution
    return np.sort(areas[areas >= min_area_m2])[::-1]


def grid_scores(state: np.ndarray, grid: MetricGrid, params: HarrisParams | None = None,
                min_area_m2: float = MIN_ENCLOSED_AREA, corners: int | None = None) -> GridScores:
    """All three figures of an occupancy raster (``state``: int8 OCCUPIED / FREE / UNKNOWN on
    ``grid``). ``corners``: :func:`corner_count` of this raster when already found (``eval``
    has the truth's Harris corners: on a large map the detector is most of the cost)."""
    occupied, free, ratio = occupied_free(state)
    areas = enclosed_areas(state, grid.resolution, min_area_m2)
    return GridScores(occupied_cells=occupied, free_cells=free, occupied_free_ratio=ratio,
                      corners=corner_count(state, grid, params) if corners is None else corners,
                      enclosed_areas=len(areas), enclosed_area_m2=float(areas.sum()))
