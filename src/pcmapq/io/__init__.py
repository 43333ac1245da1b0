"""Loading maps: occupancy images (with their ROS map_server YAML), point clouds, survey
clouds (LAS, LAZ, E57) and the OccupancyGrid messages of ROS recordings.

``load_map`` picks the loader from the file extension. Every problem with an input raises
:class:`pcmapq.core.errors.InputError` with one line naming the file; inputs are never modified.
"""

from __future__ import annotations

from pathlib import Path

from pcmapq.core.errors import InputError
from pcmapq.io.bag_grids import grid_at
from pcmapq.io.bags import is_bag
from pcmapq.io.carmen import is_carmen, load_carmen
from pcmapq.io.clouds import CLOUD_SUFFIXES, PointMap, load_cloud
from pcmapq.io.map_yaml import YAML_SUFFIXES, Thresholds
from pcmapq.io.occupancy import IMAGE_SUFFIXES, OccupancyMap, load_occupancy

__all__ = ["OccupancyMap", "PointMap", "Thresholds", "load_map"]

#: The formats named in the error for an unknown extension (others are accepted quietly).
_ADVERTISED = (".png", ".pgm", ".yaml", ".ply", ".pcd", ".xyz", ".txt", ".npy", ".bin", ".las",
               ".laz", ".e57", ".bag", ".db3", ".mcap")


def load_map(path: str | Path, resolution: float | None = None,
             fallback_resolution: float | None = None,
             thresholds: Thresholds | None = None,
             memory_limit: int | None = None, topic: str | None = None,
             at: float | None = None, topic_option: str = "--map-topic"
             ) -> OccupancyMap | PointMap:
    """Load a map file by its extension.

    Occupancy images (.png, .pgm, .jpg, .bmp) and ROS map_server YAML (.yaml, .yml) give an
    :class:`OccupancyMap`; ``resolution`` (metres per cell) overrides the YAML's, and
    ``fallback_resolution`` serves an image with neither (its scale to be estimated). Point clouds
    (.ply, .pcd, .xyz, .txt, .npy, KITTI .bin) and CARMEN laser logs (.log, .log.gz: the beam
    endpoints at the logged poses) give a :class:`PointMap`; ``resolution`` is ignored for them.
    ``thresholds`` (map_server's occupied_thresh, free_thresh, negate) override an image's YAML;
    clouds ignore them. Sizes declared in headers (an image's pixels, a .npy's rows) are checked
    against ``memory_limit`` bytes (None: :func:`pcmapq.core.memory.default_limit`) before anything
    is allocated. A ROS recording (.bag, .db3, .mcap, or a ROS 2 bag folder) gives the
    OccupancyGrid of its ``topic`` (default: the only one, or ``/map``; ``topic_option`` names
    the option in errors) at ``at`` seconds of its clock (default: the last).
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: not found")
    if is_bag(path):
        return grid_at(path, topic, at, thresholds, topic_option, memory_limit)
    if not path.is_file():
        raise InputError(f"{path}: not a file")
    if is_carmen(path):  # before the suffix test: the suffix of x.log.gz is .gz
        return load_carmen(path)
    suffix = path.suffix.lower()
    if suffix in IMAGE_SUFFIXES or suffix in YAML_SUFFIXES:
        return load_occupancy(path, resolution, fallback_resolution, thresholds, memory_limit)
    if suffix in CLOUD_SUFFIXES:
        return load_cloud(path, memory_limit)
    raise InputError(f"{path}: unsupported format '{suffix}' (expected {', '.join(_ADVERTISED)})")
