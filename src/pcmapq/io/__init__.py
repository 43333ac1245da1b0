"""Loading maps: occupancy images (with their ROS map_server YAML), point clouds, survey
clouds (LAS, LAZ, E57) and the OccupancyGrid messages of ROS recordings.

``load_map`` (:mod:`pcmapq.io.load`) picks the loader from the file extension (the suffixes:
:mod:`pcmapq.io.formats`). Every problem with an input raises
:class:`pcmapq.core.errors.InputError` with one line naming the file; inputs are never
modified. The loaders are imported on first use, so that the command line's help, which names
the formats, loads none of them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from pcmapq.io.load import load_map

if TYPE_CHECKING:
    from pcmapq.io.clouds import PointMap
    from pcmapq.io.map_yaml import Thresholds
    from pcmapq.io.occupancy import OccupancyMap

__all__ = ["OccupancyMap", "PointMap", "Thresholds", "load_map"]

#: The package's names defined by its modules, loaded on first use.
_LAZY = {"OccupancyMap": "pcmapq.io.occupancy", "PointMap": "pcmapq.io.clouds",
         "Thresholds": "pcmapq.io.map_yaml"}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
