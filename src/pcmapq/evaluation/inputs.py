"""Each input made ready to score: read and cropped as its options say, checked for an absurd
extent, its 2D structure (plan points) taken out and checked for something to align, and the
truth's grid and occupied cells, on which everything is drawn.

An input is refused with exit 2 when it is wider than :data:`pcmapq.io.extent.MAX_SPAN`, and
with exit 1 when its walls fill fewer than :data:`MIN_CELLS` cells or form one straight line
(nothing fixes a pose along it), or when more than :data:`MAX_OCCUPIED_SHARE` of an image is
occupied (not walls: a picture read inverted).
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

from pcmapq.core import memory
from pcmapq.core.bounds import bounds
from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.core.frames import Levelling
from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import outline
from pcmapq.features.walls import CLOSING
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.io.carmen import read_laser_scans
from pcmapq.io.extent import crop
from pcmapq.io.occupancy import NO_RESOLUTION, open_outside
from pcmapq.raster.draw import OCCUPIED, points_to_grid
from pcmapq.raster.seen import seen_of_scans
from pcmapq.raster.slice import wall_band
from pcmapq.settings import MIN_HITS_2D, MIN_HITS_3D, Settings, SourceConfig

#: The crop option of each side, named in messages.
MAP_CROP, TRUTH_CROP = "--map-crop", "--truth-crop"
#: The fewest distinct occupied cells (of memory.WORKING_CELL, 0.05 m) a map or truth needs to
#: be scored: fewer (one point, a few identical points, a 1x1 image) is refused, exit 1.
MIN_CELLS = 10
#: The largest share of an image's cells that may be occupied: a map of walls draws thin lines
#: on free space, a small share of its cells. More is a picture read inverted (``negate: 1`` on
#: a black-walls image, free space read above occupied_thresh) or a filled area, not walls; it
#: is refused (exit 1) before the alignment, whose cost grows with the occupied cells.
MAX_OCCUPIED_SHARE = 0.5
#: Walls narrower than this across their main direction, metres, are one straight line.
LINE_WIDTH = 0.5
#: Plan points looked at by the structure checks (a stride through larger plans).
SAMPLE = 100_000
#: An image's plan points are its occupied cells within this many metres of free or unknown
#: space: a block drawn filled (kitchen cabinets on an architect's plan, a pillar) is its
#: outline, as a laser sees it, and cannot outscore walls where a map's clutter lies on it; a
#: wall up to twice as thick stays whole.
OUTLINE_M = 0.1


def load_input(path: str | Path, config: SourceConfig, option: str,
               fallback: float | None = None,
               memory_limit: int | None = None) -> OccupancyMap | PointMap:
    """An input read as ``config`` says (resolution, thresholds; ``fallback``: the resolution of
    an image that has none) and cut to its crop box; see :func:`pcmapq.io.load_map`. An
    image's outside drawn solid is read as its face (:func:`pcmapq.io.occupancy.open_outside`)
    before the crop; a CARMEN log given as the map, uncropped, carries the area its scans saw
    (:func:`with_seen`)."""
    source = load_map(path, config.resolution, fallback, config.thresholds, memory_limit,
                      config.topic, config.at, option.replace("crop", "topic"),
                      option.replace("crop", "resolution"))
    if isinstance(source, OccupancyMap) and source.kind == "image":
        source = replace(source, state=open_outside(source.state, source.grid.resolution))
    if option == MAP_CROP and config.crop is None:
        source = with_seen(source)
    return cropped(source, config, option)


def with_seen(source: OccupancyMap | PointMap) -> OccupancyMap | PointMap:
    """A CARMEN log's map with the area its scans saw at their logged poses (its free space,
    the evidence :mod:`pcmapq.align.free_space` weighs), as ``pcmapq track`` gives its steps;
    any other input as it is."""
    if not (isinstance(source, PointMap) and source.kind == "carmen" and source.seen is None):
        return source
    return replace(source, seen=seen_of_scans(read_laser_scans(source.path), 2 * CLOSING))


def registered_in_3d(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
                     settings: Settings) -> bool:
    """Whether the map is placed by a 3D registration: both sides are 3D clouds, and no guess,
    ``--no-align`` or ``--scale auto`` says otherwise."""
    option = settings.alignment
    return all(isinstance(s, PointMap) and s.is_3d for s in (source, truth)) and \
        option.enabled and option.init is None and not option.scale


def load_pair(map_path: str | Path | PointMap, truth_path: str | Path, settings: Settings,
              memory_limit: int | None = None) -> tuple[OccupancyMap | PointMap,
                                                         OccupancyMap | PointMap]:
    """The map (or a map already built, cropped as the settings say) and the truth, read at
    once on two threads; the truth's error first, as when read one after the other, or one
    line for both when neither image has a resolution. A map of unknown unit (scale free) is
    read after the truth, from the truth's resolution."""
    scaled = settings.alignment.scale
    with ThreadPoolExecutor(1) as background:
        truth_job = background.submit(load_input, truth_path, settings.truth, TRUTH_CROP,
                                      memory_limit=memory_limit)
        try:
            source = (cropped(map_path, settings.map, MAP_CROP)
                      if isinstance(map_path, PointMap) else None if scaled else
                      load_input(map_path, settings.map, MAP_CROP, memory_limit=memory_limit))
        except InputError as map_error:
            _both(truth_job, map_error, map_path, truth_path)
            raise
        truth = truth_job.result()
    if source is None:
        guess = truth.grid.resolution if isinstance(truth, OccupancyMap) else (
            settings.truth.resolution or settings.raster.cloud_resolution)
        source = load_input(map_path, settings.map, MAP_CROP, guess, memory_limit)
    return source, truth


def _both(truth_job: Future, map_error: InputError, map_path: object,
          truth_path: object) -> None:
    """When the map failed to load: the truth's error first (InputError), as one after the
    other, or one line for both when neither image has a resolution."""
    try:
        truth_job.result()
    except InputError as truth_error:
        if all(NO_RESOLUTION in str(e) for e in (map_error, truth_error)):
            raise InputError(f"{map_path} and {truth_path}: {NO_RESOLUTION} for either: give "
                             "--map-resolution and --truth-resolution, or a YAML beside "
                             "each") from None
        raise


def cropped(source: OccupancyMap | PointMap, config: SourceConfig,
            option: str) -> OccupancyMap | PointMap:
    """The input cut to ``config.crop`` (``option`` names the crop in messages), or as it is."""
    return source if config.crop is None else crop(source, config.crop, option)


def plan_points(source: OccupancyMap | PointMap,
                settings: Settings) -> tuple[np.ndarray, Levelling | None]:
    """The 2D structure of an input, (N, 2) metres in its own plan frame: the centres of an
    image's occupied cells within OUTLINE_M of free space, the wall band of a 3D cloud (with
    the levelling that made its plan), or a 2D cloud as it is. Refused (EvaluationError)
    when it has nothing to align: see the module docstring."""
    levelling = None
    if isinstance(source, OccupancyMap):
        occupied = source.state == OCCUPIED
        xy = source.grid.cell_centres(outline(occupied, OUTLINE_M / source.grid.resolution))
    elif source.is_3d:
        try:
            xy, levelling = wall_band(source.points, settings.raster.band_low,
                                       settings.raster.band_high)
        except ValueError as err:
            raise InputError(f"{source.path}: {err}") from None
    else:
        xy = source.points[:, :2]
    if len(xy) == 0:
        why = source.empty if isinstance(source, OccupancyMap) else ""
        raise InputError(f"{source.path}: no occupied cells: {why}" if why else
                         f"{source.path}: no occupied cells or wall points")
    check_structure(source.path, xy)
    if isinstance(source, OccupancyMap):
        check_occupied_share(source, int(np.count_nonzero(occupied)))
    return xy, levelling


def check_occupied_share(source: OccupancyMap, occupied: int) -> None:
    """Refuse (EvaluationError) an image more than MAX_OCCUPIED_SHARE of whose cells are
    occupied: not a map of walls."""
    share = occupied / source.state.size
    if share > MAX_OCCUPIED_SHARE:
        raise EvaluationError(
            f"{source.path}: not a map of walls: {share:.0%} of its cells are occupied (at most "
            f"{MAX_OCCUPIED_SHARE:.0%} expected: walls are thin lines on free space); is the "
            "picture inverted? check negate, occupied_thresh and free_thresh in its YAML, or "
            "the --map-/--truth- options that override them")


def check_structure(path: Path, xy: np.ndarray) -> None:
    """EvaluationError (exit 1, one line) when the plan points ``xy`` (N, 2, metres) fill fewer
    than :data:`MIN_CELLS` cells or lie along one straight line narrower than
    :data:`LINE_WIDTH`: nothing to align or score."""
    sample = np.asarray(xy[::max(1, len(xy) // SAMPLE)], dtype=np.float64)
    cells = distinct_cells(sample)
    if cells < MIN_CELLS and len(sample) < len(xy):
        cells = distinct_cells(xy)
    if cells < MIN_CELLS:
        raise EvaluationError(f"{path}: degenerate map: its walls fill {cells} distinct "
                              f"{memory.WORKING_CELL:g} m cells, fewer than {MIN_CELLS}: "
                              "nothing to align or score")
    centred = sample - sample.mean(axis=0)
    _, axes = np.linalg.eigh(centred.T @ centred)
    along, across = centred @ axes[:, 1], centred @ axes[:, 0]
    width = float(np.ptp(np.percentile(across, [1, 99])))
    if width < LINE_WIDTH:
        raise EvaluationError(f"{path}: its walls form one straight line "
                              f"({np.ptp(along):.1f} m long, {width:.2f} m wide): nothing fixes "
                              "a pose along it; a map needs walls in two directions")


def distinct_cells(xy: np.ndarray) -> int:
    """How many distinct cells of memory.WORKING_CELL (metres) the points ``xy`` (metres) fill."""
    cells = np.floor(np.asarray(xy[:, :2]) / memory.WORKING_CELL).astype(np.int64)
    cells -= bounds(cells)[0]  # one int64 per cell: a 1D unique, not a row-wise one
    return len(np.unique(cells[:, 0] * (int(cells[:, 1].max()) + 1) + cells[:, 1]))


def min_hits(cloud: PointMap, settings: Settings) -> int:
    """Points needed to mark a cell of this cloud occupied (see RasterConfig.min_hits)."""
    if settings.raster.min_hits is not None:
        return settings.raster.min_hits
    return MIN_HITS_3D if cloud.is_3d else MIN_HITS_2D


def truth_grid(truth: OccupancyMap | PointMap, truth_xy: np.ndarray,
               settings: Settings) -> MetricGrid:
    """The grid everything is drawn on: an image's own; for a cloud, an axis-aligned grid
    around its plan points ``truth_xy`` at the truth's resolution (or the raster's
    ``cloud_resolution``). Nothing is allocated."""
    if isinstance(truth, OccupancyMap):
        return truth.grid
    return MetricGrid.covering(truth_xy,
                               settings.truth.resolution or settings.raster.cloud_resolution)


def truth_raster(truth: OccupancyMap | PointMap, truth_xy: np.ndarray,
                 settings: Settings) -> tuple[MetricGrid, np.ndarray]:
    """The truth's grid (:func:`truth_grid`) and its occupied cells."""
    grid = truth_grid(truth, truth_xy, settings)
    return grid, truth_cells(truth, truth_xy, grid, settings)


def truth_cells(truth: OccupancyMap | PointMap, truth_xy: np.ndarray, grid: MetricGrid,
                settings: Settings) -> np.ndarray:
    """The truth's occupied cells (bool) on ``grid``, the one :func:`truth_grid` planned: an
    image's own, a cloud's plan points ``truth_xy`` (metres) drawn."""
    if isinstance(truth, OccupancyMap):
        return truth.state == OCCUPIED
    return points_to_grid(truth_xy, grid, min_hits(truth, settings))
