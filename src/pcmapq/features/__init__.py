"""Feature detectors behind one registry: Harris corners, Hough wall segments, SIFT on entropy,
rooms.

Each detector is a :class:`~pcmapq.features.base.Detector` (with its parameters ``Params``, a
frozen dataclass, lengths in metres) defined by a module of this package and named in the
registry, :data:`pcmapq.features.names.DETECTOR_SOURCES`: adding a detector is adding its module
and one line there. The names are read without loading a detector; the rest
(:mod:`pcmapq.features.registry`, :mod:`pcmapq.features.base`) loads on first use, so that the
command line's help, which names the detectors, loads none of them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from pcmapq.features.names import DEFAULT_DETECTORS, DETECTOR_NAMES, DETECTOR_SOURCES

if TYPE_CHECKING:
    from pcmapq.features.base import Candidates, Detector, Features
    from pcmapq.features.registry import (
        DETECTORS,
        SideBySide,
        default_params,
        detect,
        detect_in,
        detector,
        walls_of,
    )
    from pcmapq.features.walls import WallImage

__all__ = ["DEFAULT_DETECTORS", "DETECTORS", "DETECTOR_NAMES", "DETECTOR_SOURCES", "Candidates",
           "Detector", "Features", "SideBySide", "WallImage", "default_params", "detect",
           "detect_in", "detector", "walls_of"]

#: The package's names defined by its modules, loaded on first use.
_LAZY = {"Candidates": "base", "Detector": "base", "Features": "base", "WallImage": "walls",
         **{name: "registry" for name in ("DETECTORS", "SideBySide", "default_params", "detect",
                                          "detect_in", "detector", "walls_of")}}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
