"""The detectors' registry and running them: the detectors named in
:data:`pcmapq.features.names.DETECTOR_SOURCES`, each a :class:`~pcmapq.features.base.Detector`
with its ``Params`` (a frozen dataclass, lengths in metres); the walls every detector sees, and
the two sides' detectors run side by side. Its names are re-exported by :mod:`pcmapq.features`.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from threading import BoundedSemaphore, Event, Lock
from typing import Any

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.features.base import Detector, Features
from pcmapq.features.names import DETECTOR_SOURCES
from pcmapq.features.walls import WallImage, wall_image

__all__ = ["DETECTORS", "SideBySide", "default_params", "detect", "detect_in", "detector",
           "load", "walls_of"]


def _load(name: str, source: str) -> Detector:
    """The detector ``name`` defined at ``source`` (``module:attribute``)."""
    module, _, attribute = source.partition(":")
    found = getattr(importlib.import_module(module), attribute)
    if not isinstance(found, Detector) or found.name != name:
        raise TypeError(f"{source} is not the Detector {name!r}")
    return found


def load(sources: Mapping[str, str]) -> dict[str, Detector]:
    """The detectors of a registry (name -> ``module:attribute``), by name, in its order."""
    return {name: _load(name, source) for name, source in sources.items()}


#: The detectors by name, those of :data:`pcmapq.features.names.DETECTOR_SOURCES` in its order:
#: "harris", "hough", "sift" (the paper's), then "rooms".
DETECTORS: dict[str, Detector] = load(DETECTOR_SOURCES)


def detector(name: str) -> Detector:
    """The detector ``name`` (a key of :data:`DETECTORS`); InputError for an unknown name."""
    if name not in DETECTORS:
        raise InputError(f"unknown feature detector {name!r}; known: {', '.join(DETECTORS)}")
    return DETECTORS[name]


def default_params() -> dict[str, Any]:
    """The default parameters of the detectors run by default, by name: frozen dataclasses,
    lengths in metres; ``dataclasses.asdict`` of each is plain JSON. Any other detector run
    takes its own defaults (``DETECTORS[name].params()``)."""
    return {name: d.params() for name, d in DETECTORS.items() if d.by_default}


#: Detectors running at once in the process, over both sides and every map: as many as there
#: are cores (at least 2). More only stack their largest temporaries (an 8000^2 SIFT scale
#: space beside another side's Harris and Hough) on a machine that cannot run them faster.
_DETECTING = BoundedSemaphore(max(2, os.cpu_count() or 1))


def walls_of(occupied: np.ndarray, grid: MetricGrid) -> WallImage:
    """The walls of a binary map as every detector sees them (see :mod:`pcmapq.features.walls`).

    occupied : (rows, cols) bool raster drawn on ``grid``, walls true.
    """
    occupied = np.asarray(occupied, dtype=bool)
    if occupied.shape != tuple(grid.shape):
        raise InputError(f"raster shape {occupied.shape} does not match grid shape {grid.shape}")
    return wall_image(occupied, grid)


def detect_in(name: str, walls: WallImage, params: Any = None) -> Features:
    """Features of detector ``name`` (a key of :data:`DETECTORS`) in ``walls``, in the metric
    frame of its grid; ``params`` are the detector's own (its ``Params``, lengths in metres),
    its defaults when None. Waits while as many detectors as the process allows run
    (``_DETECTING``)."""
    found = detector(name)
    with _DETECTING:
        return found.detect(walls, found.checked(params))


class SideBySide:
    """The truth's and the map's features, each side on its own thread (:meth:`features`):
    the truth's start as soon as its raster exists, while the map is still being aligned.

    One side at a time runs a given detector, and a side takes the next of its detectors that
    the other side is not running (waiting only when all that are left are busy): the two
    sides' largest temporaries (SIFT's scale space) never coincide, neither side idles while
    there is work the other does not hold, and one side's Python-bound steps (Hough's merging)
    overlap the other's OpenCV and NumPy work, which runs without the interpreter lock. No more
    detectors run at once in the process than it has cores (at least 2; :func:`detect_in`),
    whichever side or caller runs them. Each result depends on its own input only, whichever
    thread computes it and in whatever order.
    :meth:`cancel` stops a side at its next detector (a refused map needs no truth features)."""

    def __init__(self, names: Sequence[str], params: Mapping[str, Any]) -> None:
        """names: the detectors (keys of :data:`DETECTORS`, unknown ones fail here); params:
        their parameters by name (missing: the defaults)."""
        self.names, self.params = list(names), params
        for name in self.names:
            detector(name)
        self._busy = {name: Lock() for name in self.names}
        self._stop = Event()

    def features(self, occupied: np.ndarray, grid: MetricGrid,
                 threads: int = 1) -> dict[str, Features]:
        """Every detector's features on one side's occupied cells (bool on ``grid``), on up to
        ``threads`` threads of this side (this one included); only those found before a
        :meth:`cancel`."""
        walls = walls_of(occupied, grid)
        found: dict[str, Features] = {}
        left, taking = list(self.names), Lock()

        def work() -> None:
            while not self._stop.is_set():
                with taking:  # the first detector left that is free, else the first left
                    if not left:
                        return
                    free = next((n for n in left if self._busy[n].acquire(blocking=False)),
                                None)
                    name = left[0] if free is None else free
                    left.remove(name)
                if free is None:
                    self._busy[name].acquire()
                try:
                    found[name] = detect_in(name, walls, self.params.get(name))
                finally:
                    self._busy[name].release()

        with ThreadPoolExecutor(max(threads - 1, 1)) as more:
            others = [more.submit(work) for _ in range(threads - 1)]
            work()
            for other in others:
                other.result()
        return found

    def cancel(self) -> None:
        """Stop every side at its next detector."""
        self._stop.set()


def detect(name: str, occupied: np.ndarray, grid: MetricGrid, params: Any = None) -> Features:
    """Features of detector ``name`` on a binary map: :func:`detect_in` of :func:`walls_of`.

    Parameters
    ----------
    name : a key of :data:`DETECTORS`.
    occupied : (rows, cols) bool raster drawn on ``grid``, walls true.
    grid : the raster's grid; features are in its metric frame, metres.
    params : the detector's parameters (its ``Params``, lengths in metres); None: its defaults.
    """
    return detect_in(name, walls_of(occupied, grid), params)
