"""The detectors' names and the distance their features match within, apart from the detectors
(which load OpenCV, SciPy and Numba) and the matching (SciPy), so the settings and the command
line's help name them without loading any. A detector added as a module of
:mod:`pcmapq.features` is named here too: a test holds these to the registry
(:data:`pcmapq.features.registry.DETECTORS`: its order, and which run by default)."""

from __future__ import annotations

#: Every detector, the paper's first (Harris, Hough, SIFT), then the others, each group in
#: alphabetical order.
DETECTOR_NAMES: tuple[str, ...] = ("harris", "hough", "sift", "rooms")
#: The detectors an evaluation runs when none are named.
DEFAULT_DETECTORS: tuple[str, ...] = ("harris", "hough", "sift", "rooms")
#: Largest distance between matched features by default, metres: ``MatchingConfig.threshold``
#: (``--threshold``) and :func:`pcmapq.match.match`'s default.
MATCH_THRESHOLD = 0.5
