"""The footprint rules' names, apart from :mod:`pcmapq.raster.footprint` (which loads OpenCV
and SciPy), so the settings and the command line's help name them without it."""

from __future__ import annotations

#: The footprint rules, ``auto`` first (the default); :mod:`pcmapq.raster.footprint` says what
#: each keeps.
FOOTPRINT_RULES = ("auto", "known", "walls", "seen", "all")
