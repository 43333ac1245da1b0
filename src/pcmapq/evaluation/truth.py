"""The truth prepared once for any map (:func:`prepare_truth`): its plan points, its grid in
its own metric frame, its occupied cells, features and distance field. ``pcmapq eval``
prepares it for one map, ``pcmapq track`` for every step of a run."""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from threading import Lock

import numpy as np

from pcmapq.align.planar import RigidTarget
from pcmapq.core import memory
from pcmapq.core.frames import Levelling
from pcmapq.core.grid import MetricGrid
from pcmapq.core.priority import lower_priority
from pcmapq.evaluation.inputs import (
    MAP_CROP,
    TRUTH_CROP,
    plan_points,
    registered_in_3d,
    truth_cells,
    truth_grid,
)
from pcmapq.features import Features, SideBySide
from pcmapq.features.planes3d import PlaneParams, Planes, find_planes
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.extent import check_span, hint
from pcmapq.metrics.distances import DistanceField, nearest_distance
from pcmapq.settings import Settings, StructuresConfig

#: Threads that find a truth's features when nothing else runs beside them.
FEATURE_THREADS = 2


class PlanesOnce:
    """A 3D cloud truth's planes, found the first time a score asks for them and kept for
    every later one (the steps of ``pcmapq track``): a job as
    :func:`~pcmapq.evaluation.scoring.structures_3d` takes one, that cannot be cancelled.
    Safe from several threads at once: the first finds them, the others wait."""

    def __init__(self, points: np.ndarray, params: PlaneParams) -> None:
        self._points, self._params = points, params
        self._planes: Planes | None = None
        self._finding = Lock()

    def cancel(self) -> bool:
        return False

    def result(self) -> Planes:
        with self._finding:
            if self._planes is None:
                self._planes = find_planes(self._points, self._params)
            return self._planes


@dataclass(frozen=True)
class PreparedTruth:
    """The truth as every score against it needs it, whatever the map: its plan points ``xy``
    (N, 2) metres with the ``level`` that made them, the ``grid`` everything is drawn on, its
    ``occupied`` cells, its :attr:`features` by detector (``found``: them, or their job on a
    background thread), ``to_truth``: each cell's distance to the nearest truth wall, metres;
    ``aligner``: its points prepared for the rigid alignment; ``maps``: how many maps may be
    scored on its grid at once in the memory allowed; ``sides``: the detectors' runner (the
    maps' sides join it; it stops a background job whose map is refused); ``planes``: the job
    finding a 3D cloud truth's planes for the 3D structures (:func:`plane_params`; for every
    map scored against it, a :class:`PlanesOnce`), or None (found with the map's)."""

    source: OccupancyMap | PointMap
    xy: np.ndarray
    level: Levelling | None
    grid: MetricGrid
    occupied: np.ndarray
    found: dict[str, Features] | Future
    to_truth: DistanceField | None = None
    aligner: RigidTarget | None = None
    maps: int = 1
    sides: SideBySide | None = None
    planes: Future[Planes] | PlanesOnce | None = None

    @property
    def features(self) -> dict[str, Features]:
        """The truth's features by detector (waiting for the background job, if any)."""
        return self.found.result() if isinstance(self.found, Future) else self.found

    def cancel(self) -> None:
        """Stop the background jobs, if any (their map was refused or failed): the features
        between two detectors, the planes unless already started."""
        if self.sides is not None:
            self.sides.cancel()
        if self.planes is not None:
            self.planes.cancel()


def prepare_truth(truth: OccupancyMap | PointMap, settings: Settings,
                  memory_limit: int | None = None, maps: tuple[int, ...] = (1,),
                  loaded: Sequence[OccupancyMap | PointMap] = (),
                  background: bool = False) -> PreparedTruth:
    """Everything of the truth that does not depend on the map.

    maps: how many maps the caller would score on its grid at once beyond the first, most
    wanted first; the first whose estimated memory fits in ``memory_limit`` bytes (None: the
    default) is kept as ``PreparedTruth.maps``; InputError (one line) when none fits.
    loaded: inputs held in memory beside the truth (``eval``'s map), counted in the estimate.
    background: find the features on a thread of their own while the caller places its map
    (:meth:`PreparedTruth.features` waits for them), and after them a 3D cloud truth's planes
    when a 3D cloud map is to be registered to it with its structures found (the map's 3D
    registration leaves a core free: :mod:`pcmapq.align.refine3d`); otherwise the features
    here, on two threads, and a 3D cloud truth's planes once the first map asks for them."""
    check_span(truth, TRUTH_CROP)
    for source in loaded:
        check_span(source, MAP_CROP)
    xy, level = plan_points(truth, settings)
    grid = truth_grid(truth, xy, settings)
    need = {n: needed_memory((*loaded, truth), grid, n) for n in maps}
    limit = memory.default_limit() if memory_limit is None else memory_limit
    fits = [n for n in maps if need[n] <= limit]
    least = min(maps)
    what = (f"{loaded[0].path} against {truth.path}" if loaded else
            f"{truth.path} with {least} map{'s' * (least > 1)} scored on its grid")
    memory.guard(need[fits[0] if fits else least], memory_limit, what,
                 lambda: hint(truth, TRUTH_CROP, grid.resolution)
                 or next((h for s in loaded if (h := hint(s, MAP_CROP))), None)
                 or memory_advice((*loaded, truth), grid, least, limit))
    occupied = truth_cells(truth, xy, grid, settings)
    sides = SideBySide(settings.matching.detectors, settings.matching.params)
    option = settings.alignment
    planes = None
    if background:
        pool = ThreadPoolExecutor(1, initializer=lower_priority)
        found: dict[str, Features] | Future = pool.submit(sides.features, occupied, grid)
        if settings.structures.enabled and \
                any(registered_in_3d(source, truth, settings) for source in loaded):
            planes = pool.submit(find_planes, truth.points, plane_params(settings.structures))
        pool.shutdown(wait=False)  # its thread ends with the jobs
    else:
        found = sides.features(occupied, grid, threads=FEATURE_THREADS)
        if settings.structures.enabled and isinstance(truth, PointMap) and truth.is_3d:
            planes = PlanesOnce(truth.points, plane_params(settings.structures))
    aligner = RigidTarget(xy, option.params) if option.enabled and not option.scale else None
    return PreparedTruth(truth, xy, level, grid, occupied, found, nearest_distance(occupied, grid),
                         aligner, fits[0] if fits else least, sides, planes)


def plane_params(option: StructuresConfig) -> PlaneParams:
    """The parameters the 3D structures' planes are found with."""
    return PlaneParams(option.voxel, option.min_points, option.min_area)


def _sizes(inputs: Sequence[OccupancyMap | PointMap],
           grid: MetricGrid) -> tuple[int, int, float, int]:
    """Image cells, grid cells, the grid's area (m^2) and cloud points of scoring on ``grid``."""
    images = sum(int(np.prod(s.grid.shape)) for s in inputs if isinstance(s, OccupancyMap))
    points = sum(len(s.points) for s in inputs if isinstance(s, PointMap))
    cells = int(np.prod(grid.shape))
    return images, cells, cells * grid.resolution**2, points


def needed_memory(inputs: Sequence[OccupancyMap | PointMap], grid: MetricGrid,
                  more_maps: int = 0) -> int:
    """Estimated peak memory, bytes, of scoring a map against a truth (``inputs``: both, or
    the truth alone for what it needs whatever the map) on the truth's ``grid``, with
    ``more_maps`` maps more scored on it at once: see :mod:`pcmapq.core.memory`."""
    images, cells, extent, points = _sizes(inputs, grid)
    one_map = memory.needed_bytes(0, cells, extent, 0) - memory.BASE
    return memory.needed_bytes(images, cells, extent, points) + more_maps * one_map


#: Cell sizes, metres, a cloud truth's grid may be made coarser to (``--truth-resolution``).
COARSER = (0.05, 0.1, 0.2, 0.5, 1.0)


def memory_advice(inputs: Sequence[OccupancyMap | PointMap], grid: MetricGrid,
                  more_maps: int, limit: int) -> str:
    """What most of the memory a run needs on ``grid`` is for, and only what would help within
    ``limit`` bytes, one clause: a cloud truth's grid at a coarser ``--truth-resolution`` when
    that would fit (the detectors' working cells, :data:`memory.WORKING_CELL` over the grid's
    area, are the same whatever it is), a crop (unless the libraries alone exceed the limit),
    a higher ``--max-memory`` when this machine has that much. ``--voxel-3d`` changes no part
    of the estimate, and is not named."""
    need = needed_memory(inputs, grid, more_maps)
    images, cells, extent, points = _sizes(inputs, grid)
    maps = 1 + more_maps
    part = memory.parts(images, cells * maps, extent * maps, points)
    largest = max(part, key=part.__getitem__)
    width, height = grid.size_m
    what = {"images": f"the images' {images:,} pixels",
            "grid": f"the truth's grid of {cells:,} cells of {grid.resolution:g} m",
            "working": f"the detectors' {memory.WORKING_CELL:g} m cells over the truth's "
                       f"{width:,.0f} x {height:,.0f} m, whatever --truth-resolution",
            "points": f"the clouds' {points:,} points"}[largest]
    fixes = []
    truth = inputs[-1]
    if isinstance(truth, PointMap):
        for cell in (c for c in COARSER if c > grid.resolution):
            coarse = MetricGrid(cell, grid.origin, (max(1, round(height / cell)),
                                                    max(1, round(width / cell))))
            fits = needed_memory(inputs, coarse, more_maps)
            if fits <= limit:
                fixes.append(f"--truth-resolution {cell:g} needs about {fits / 1e9:,.1f} GB")
                break
    if memory.BASE < limit:
        fixes.append("inputs cropped to the region of interest (--map-crop, --truth-crop) "
                     "need less")
    machine = memory.machine_bytes()
    if need < machine:
        fixes.append(f"a --max-memory of {need / 1e9:,.1f} GB or more runs it, if this "
                     f"machine's {machine / 1e9:.1f} GB can spare that")
    return f"{part[largest] / 1e9:,.1f} GB of it for {what}: {'; or '.join(fixes)}"
