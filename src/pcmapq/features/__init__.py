"""Feature detectors behind one registry: Harris corners, Hough wall segments, SIFT on entropy.

Each detector is a module of this package that defines ``DETECTOR`` (a
:class:`~pcmapq.features.base.Detector`): adding a detector is adding a file.
"""

from __future__ import annotations

import importlib
import pkgutil

import numpy as np

from pcmapq.errors import InputError
from pcmapq.features.base import Candidates, Detector, Features
from pcmapq.grid import MetricGrid

__all__ = ["DETECTORS", "Candidates", "Detector", "Features", "detect"]


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


def detect(name: str, occupied: np.ndarray, grid: MetricGrid, **params) -> Features:
    """Features of detector ``name`` on a binary map.

    Parameters
    ----------
    name : a key of :data:`DETECTORS`.
    occupied : (rows, cols) bool raster drawn on ``grid``, walls true.
    grid : the raster's grid; features are in its metric frame, metres.
    **params : the detector's own parameters (see its ``detect``), lengths in metres.
    """
    if name not in DETECTORS:
        raise InputError(f"unknown feature detector {name!r}; known: {', '.join(DETECTORS)}")
    occupied = np.asarray(occupied, dtype=bool)
    if occupied.shape != tuple(grid.shape):
        raise InputError(f"raster shape {occupied.shape} does not match grid shape {grid.shape}")
    return DETECTORS[name].detect(occupied, grid, **params)
