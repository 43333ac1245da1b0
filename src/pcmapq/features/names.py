"""The detectors' registry: each detector's name and where it is defined, apart from the
detectors themselves (which load OpenCV, SciPy and Numba), so the settings and the command
line's help name them without loading any. :mod:`pcmapq.features.registry` loads the detectors
listed here, and only those."""

from __future__ import annotations

#: Every detector by name, in the order they are run, written and drawn: the paper's (Harris,
#: Hough, SIFT), then the others. Each value names a
#: :class:`~pcmapq.features.base.Detector` as ``module:attribute``. Adding a detector is one
#: line here; a module of :mod:`pcmapq.features` not named here is never run.
DETECTOR_SOURCES: dict[str, str] = {
    "harris": "pcmapq.features.harris:DETECTOR",
    "hough": "pcmapq.features.hough:DETECTOR",
    "sift": "pcmapq.features.sift:DETECTOR",
    "rooms": "pcmapq.features.rooms:DETECTOR",
}

#: Every detector's name, in the registry's order.
DETECTOR_NAMES: tuple[str, ...] = tuple(DETECTOR_SOURCES)
#: The detectors an evaluation runs when none are named: every one (a detector run only when
#: named is left out here, and says ``by_default=False``).
DEFAULT_DETECTORS: tuple[str, ...] = DETECTOR_NAMES
#: Largest distance between matched features by default, metres: ``MatchingConfig.threshold``
#: (``--threshold``) and :func:`pcmapq.match.match`'s default.
MATCH_THRESHOLD = 0.5

#: The detectors of 3D structures of two 3D clouds (:mod:`pcmapq.match.structures`), in the
#: order they are written and shown.
STRUCTURE_NAMES: tuple[str, ...] = ("planes", "plane_lines")
