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
from threading import BoundedSemaphore, Condition, Event
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


#: The order a side takes its detectors in: the costliest first (SIFT's scale space, then the
#: rooms' segmentation), so that the last detectors of a run, whichever thread takes them, are
#: short. Others after them, in the order asked.
COSTLIEST_FIRST = ("sift", "rooms", "hough", "harris")
_RANK = {name: k for k, name in enumerate(COSTLIEST_FIRST)}


class _Side:
    """One side's detectors in :class:`SideBySide`: its walls, the detectors no thread has
    taken, how many taken are still running, what they found (or the first error)."""

    def __init__(self, walls: WallImage, names: Sequence[str]) -> None:
        self.walls, self.running = walls, 0
        self.left = sorted(names, key=lambda name: _RANK.get(name, len(_RANK)))  # stable
        self.found: dict[str, Features] = {}
        self.error: BaseException | None = None


class SideBySide:
    """The truth's and the maps' features, each side on threads of its own (:meth:`features`):
    the truth's start as soon as its raster exists, while the map is still being aligned.

    A side's thread takes the first of its detectors (:data:`COSTLIEST_FIRST`) that no other
    side is running (the sides' largest temporaries, SIFT's scale spaces, then rarely coincide;
    one side's Python-bound steps, Hough's merging, overlap the other's OpenCV and NumPy work,
    which runs without the interpreter lock), else the first left. A thread whose side has none
    left takes one another side has not started, and runs it for that side: the truth's thread
    runs at a lower priority (while the map is placed), and the last detectors of the side that
    started first need not end the run on one core. No more detectors run at once in the
    process than it has cores (at least 2; :func:`detect_in`), whichever side or caller runs
    them. Each result depends on its own input only, whichever thread computes it and in
    whatever order. :meth:`cancel` stops every side at its next detector (a refused map needs
    no truth features)."""

    def __init__(self, names: Sequence[str], params: Mapping[str, Any]) -> None:
        """names: the detectors (keys of :data:`DETECTORS`, unknown ones fail here); params:
        their parameters by name (missing: the defaults)."""
        self.names, self.params = list(names), params
        for name in self.names:
            detector(name)
        self._sides: list[_Side] = []
        self._running = {name: 0 for name in self.names}  # sides running each detector
        self._changed = Condition()
        self._stop = Event()

    def features(self, occupied: np.ndarray, grid: MetricGrid,
                 threads: int = 1) -> dict[str, Features]:
        """Every detector's features on one side's occupied cells (bool on ``grid``), on up to
        ``threads`` threads of this side (this one included) and those of other sides with
        none of their own left; only those found before a :meth:`cancel`."""
        side = _Side(walls_of(occupied, grid), self.names)
        with self._changed:
            self._sides.append(side)
        try:
            with ThreadPoolExecutor(max(threads - 1, 1)) as more:
                others = [more.submit(self._work, side) for _ in range(threads - 1)]
                self._work(side)
                for other in others:
                    other.result()
            with self._changed:  # the detectors other sides' threads took from this one
                self._changed.wait_for(lambda: side.running == 0)
        finally:
            with self._changed:
                self._sides.remove(side)
        if side.error is not None:
            raise side.error
        return {name: side.found[name] for name in self.names if name in side.found}

    def _work(self, own: _Side) -> None:
        """Run detectors, this side's first, then those other sides have not started."""
        while (job := self._take(own)) is not None:
            side, name = job
            found = failed = None
            try:
                found = detect_in(name, side.walls, self.params.get(name))
            except BaseException as error:  # raised by the side's own call
                failed = error
                if not isinstance(error, Exception):  # an interrupt stops this thread too
                    raise
            finally:
                with self._changed:
                    if found is not None:
                        side.found[name] = found
                    side.error = side.error or failed
                    side.running -= 1
                    self._running[name] -= 1
                    self._changed.notify_all()

    def _take(self, own: _Side) -> tuple[_Side, str] | None:
        """The next (side, detector) for a thread of ``own`` (class docstring), marked as
        running; None when there is none or the sides are stopped."""
        with self._changed:
            if self._stop.is_set() or own.error is not None:
                return None
            if own.left:
                side = own
                name = next((n for n in own.left if not self._running[n]), own.left[0])
            else:
                side = next((s for s in self._sides if s.left and s.error is None), None)
                if side is None:
                    return None
                name = side.left[0]
            side.left.remove(name)
            side.running += 1
            self._running[name] += 1
            return side, name

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
