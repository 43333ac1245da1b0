"""Feature detectors behind one registry: Harris corners, Hough wall segments, SIFT on entropy.

Each detector is a module of this package that defines ``DETECTOR`` (a
:class:`~pcmapq.features.base.Detector`) and its parameters ``Params`` (a frozen dataclass,
lengths in metres): adding a detector is adding a file.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from threading import Lock
from typing import Any

import numpy as np

from pcmapq.errors import InputError
from pcmapq.features.base import Candidates, Detector, Features
from pcmapq.features.walls import WallImage, wall_image
from pcmapq.grid import MetricGrid

__all__ = ["DETECTORS", "Candidates", "Detector", "Features", "WallImage", "default_params",
           "detect", "detect_both", "detect_in", "detector", "walls_of"]


def _discover() -> dict[str, Detector]:
    """Every ``DETECTOR`` defined by a module of this package, by name."""
    found = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__name__}.{info.name}")
        detector = getattr(module, "DETECTOR", None)
        if isinstance(detector, Detector):
            found[detector.name] = detector
    return found


#: The detectors by name: "harris", "hough", "sift".
DETECTORS: dict[str, Detector] = _discover()


def detector(name: str) -> Detector:
    """The detector ``name`` (a key of :data:`DETECTORS`); InputError for an unknown name."""
    if name not in DETECTORS:
        raise InputError(f"unknown feature detector {name!r}; known: {', '.join(DETECTORS)}")
    return DETECTORS[name]


def default_params() -> dict[str, Any]:
    """Every detector's default parameters by name: frozen dataclasses, lengths in metres;
    ``dataclasses.asdict`` of each is plain JSON."""
    return {name: d.params() for name, d in DETECTORS.items()}


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
    its defaults when None."""
    found = detector(name)
    return found.detect(walls, found.checked(params))


def detect_both(truth: np.ndarray, map_: np.ndarray, grid: MetricGrid, names: Sequence[str],
                params: Mapping[str, Any], progress: Callable[[str], None] = lambda step: None
                ) -> tuple[dict[str, Features], dict[str, Features]]:
    """:func:`detect` of every detector of ``names`` (with ``params.get(name)``) on the truth's
    and the map's occupied cells (bool, both on ``grid``), the two sides side by side on two
    threads: first both sides' walls (:func:`walls_of`), then the detectors, the map's in the
    reverse order and one side at a time per detector. So the two sides' largest temporaries
    (SIFT's scale space) never coincide, and one side's Python-bound steps (Hough's merging)
    overlap the other's OpenCV and NumPy work, which runs without the interpreter lock. Each
    result depends on its own input only, whichever thread computes it. ``progress`` hears
    each stage's name as it starts."""
    names = list(names)
    for name in names:
        detector(name)  # unknown names fail here, before any work
    busy = {name: Lock() for name in names}

    def side(walls: WallImage, order: list[str]) -> dict[str, Features]:
        found = {}
        for name in order:
            with busy[name]:
                found[name] = detect_in(name, walls, params.get(name))
        return found

    with ThreadPoolExecutor(2) as pool:
        progress("drawing the walls' centre lines")
        truth_walls, map_walls = pool.map(walls_of, (truth, map_), (grid, grid))
        progress(f"detecting {', '.join(names)}")
        truth_found = pool.submit(side, truth_walls, names)
        map_found = pool.submit(side, map_walls, names[::-1])
        return truth_found.result(), map_found.result()


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
