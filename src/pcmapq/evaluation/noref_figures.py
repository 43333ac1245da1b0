"""The no-reference figures of one loaded input, map or truth: what ``pcmapq inspect`` reports
and ``pcmapq eval`` reports for both sides under ``"noref"``. A 3D cloud gets MME, MPV and MOM
(:mod:`pcmapq.metrics.inspection`, as map-metrics defines them); an image or a 2D cloud gets the
occupancy figures of :mod:`pcmapq.metrics.noref2d`. docs/metrics.md says what each can tell.
"""

from __future__ import annotations

import threading
from dataclasses import asdict, replace
from typing import Any

import numpy as np

from pcmapq.core.heap import release_free_memory
from pcmapq.core.priority import lower_priority
from pcmapq.core.voxels import STRIPE_POINTS, stripe_points, voxel_centroids
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
        points = reduced(source.points, config.voxel, scale)
        planes = None if orth_subset is None else [p * scale for p in orth_subset]
        figures = noref_figures(points, config.radius, config.min_knn, config.max_nn, planes,
                                max_ward=config.max_ward, sample=config.sample)
        return {"cloud": {**figures, "voxel_m": config.voxel}, "grid": None}
    return {"cloud": None, "grid": occupancy_figures(source, scale, corners)}


def reduced(points: np.ndarray, voxel: float, scale: float = 1.0) -> np.ndarray:
    """(M, 3) float64: ``points`` times ``scale``, metres, reduced to their centroid in each
    voxel of ``voxel`` metres (0: all of them); a large cloud mapped onto its file is read in
    chunks, never converted whole (:func:`~pcmapq.core.voxels.voxel_centroids`)."""
    if voxel <= 0:
        return np.asarray(points, dtype=np.float64) * scale
    return voxel_centroids(points, voxel, scale, stripe_points=stripe_points(len(points)))


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


#: A map cloud of more than this many points, reduced in one pass (at most STRIPE_POINTS), has
#: its figures wait for its plan points (:meth:`EarlyFigures.walls_found`): its wall band is
#: shorter than the reduction beside it, and the band's end is the evaluation's first peak in
#: memory, which the figures' voxel table would raise; after it the table stands beside less. A
#: cloud reduced in stripes starts at once: its wall band is long enough for the reduction to
#: end within it, and after it the table would stand beside the plan's global search, that
#: run's peak (docs/benchmarks.md).
DEFER_FROM = 2_000_000


class EarlyFigures:
    """The no-reference figures of an evaluation's 3D clouds and of an image map, found on a
    thread of their own while the map is placed (they need neither the alignment nor the
    truth's features). A map refused before its figures are wanted waits only for the input
    the thread is on (:meth:`cancel`). A map whose scale is estimated, a 2D cloud, and an image
    truth (whose corners the truth's own Harris features give) are left to
    :func:`input_figures` after the alignment. With a map cloud of DEFER_FROM to
    STRIPE_POINTS points the thread starts its work once :meth:`walls_found` is called (or
    the figures are wanted). A side the thread has not started when the caller is free
    (:meth:`help`) is found on the caller's thread."""

    def __init__(self, sides: dict[str, OccupancyMap | PointMap], settings: Settings) -> None:
        self._config = config = settings.noref
        self._sources = {} if not config.enabled else {
            side: source for side, source in sides.items()
            if not (side == "map" and settings.alignment.scale)
            and ((isinstance(source, PointMap) and source.is_3d)
                 or (side == "map" and isinstance(source, OccupancyMap)))}
        self._figures: dict[str, dict[str, Any]] = {}
        self._left = list(self._sources)  # the sides no thread has started, in order
        self._taking = threading.Lock()
        self._error: BaseException | None = None
        self._go, self._cancelled = threading.Event(), False
        cloud = sides.get("map")
        if not (isinstance(cloud, PointMap) and DEFER_FROM < len(cloud.points) <= STRIPE_POINTS):
            self._go.set()
        self._thread = threading.Thread(target=self._run, daemon=True, name="pcmapq-noref")
        if self._sources:
            self._thread.start()

    def walls_found(self) -> None:
        """The map's plan points are found: a deferred thread may start."""
        self._go.set()

    def cancel(self) -> None:
        """The evaluation stopped: a thread still waiting to start does no work, a running one
        stops after the input it is on, and this returns when it has: a process that exits
        while the thread is inside a library's compiled code is aborted by that library
        ("terminate called without an active exception"), after its error line."""
        self._cancelled = True
        self._go.set()
        if self._thread.is_alive():
            self._thread.join()

    def help(self) -> None:
        """Find here, on the calling thread, the figures of every side the thread has not
        started (scoring, its own work done, waits for the rest: the figures of both sides of a
        large pair then take two cores rather than one); the same figures, whichever thread
        finds them. An error is raised here."""
        self._go.set()
        self._work()

    def _run(self) -> None:
        lower_priority()
        self._go.wait()
        try:
            self._work()
        except BaseException as exc:  # handed to the caller by get()
            self._error = exc

    def _work(self) -> None:
        """Find the figures of the sides left, one at a time, until none is left."""
        found = False
        while not self._cancelled:
            with self._taking:
                if not self._left:
                    break
                side = self._left.pop(0)
            self._figures[side] = input_figures(self._sources[side], self._config)
            found = True
        if found:
            release_free_memory()  # the reduction's table and chunks, freed into the heap

    def get(self, side: str) -> dict[str, Any] | None:
        """The figures of ``side`` ("map" or "truth") when found here, waiting for them; None
        when this side was left to the caller."""
        if side not in self._sources:
            return None
        self._go.set()
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._figures[side]
