"""Loading any map by its file's extension: the loader each suffix takes (the suffixes:
:mod:`pcmapq.io.formats`), and the one-line problem of a file or folder none reads. Each loader
is imported when its file is loaded."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from pcmapq.core.errors import InputError
from pcmapq.io.formats import (
    BAG_FOLDER,
    CARMEN_SUFFIXES,
    CLOUD_SUFFIXES,
    IMAGE_SUFFIXES,
    MAP_SUFFIXES,
    SCAN_SUFFIXES,
    YAML_SUFFIXES,
)

if TYPE_CHECKING:
    from pcmapq.io.clouds import PointMap
    from pcmapq.io.map_yaml import Thresholds
    from pcmapq.io.occupancy import OccupancyMap

__all__ = ["folder_problem", "load_map", "unsupported"]


def load_map(path: str | Path, resolution: float | None = None,
             fallback_resolution: float | None = None,
             thresholds: Thresholds | None = None,
             memory_limit: int | None = None, topic: str | None = None,
             at: float | None = None, topic_option: str = "--map-topic",
             resolution_option: str = "--map-resolution") -> OccupancyMap | PointMap:
    """Load a map file by its extension.

    Occupancy images (.png, .pgm, .jpg, .jpeg, .bmp) and ROS map_server YAML (.yaml, .yml)
    give an :class:`OccupancyMap`; ``resolution`` (metres per cell) overrides the YAML's, and
    ``fallback_resolution`` serves an image with neither (its scale to be estimated;
    ``resolution_option`` names the option that gives one in errors). Point clouds (.ply, .pcd,
    .xyz, .txt, .npy, KITTI .bin, .las, .laz, .e57) and CARMEN laser logs (.log, .log.gz: the
    beam endpoints at the logged poses) give a :class:`PointMap`; ``resolution`` is ignored for
    them. ``thresholds`` (map_server's occupied_thresh, free_thresh, negate) override an
    image's YAML; clouds ignore them. Sizes declared in headers (an image's pixels, a .npy's
    rows) are checked against ``memory_limit`` bytes (None:
    :func:`pcmapq.core.memory.default_limit`) before anything is allocated. A ROS recording
    (.bag, .db3, .mcap, or a ROS 2 bag folder) gives the OccupancyGrid of its ``topic``
    (default: the only one, or ``/map``; ``topic_option`` names the option in errors) at ``at``
    seconds of its clock (default: the last). A folder of scans is refused, naming ``--scans``.
    """
    from pcmapq.io.bags import is_bag

    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: not found")
    if is_bag(path):
        from pcmapq.io.bag_grids import grid_at

        return grid_at(path, topic, at, thresholds, topic_option, memory_limit)
    if path.is_dir():
        raise InputError(f"{path}: {folder_problem(path)}")
    if not path.is_file():
        raise InputError(f"{path}: not a file")
    if path.name.lower().endswith(CARMEN_SUFFIXES):  # before the suffix: x.log.gz ends .gz
        from pcmapq.io.carmen import load_carmen

        return load_carmen(path)
    suffix = path.suffix.lower()
    if suffix in IMAGE_SUFFIXES or suffix in YAML_SUFFIXES:
        from pcmapq.io.occupancy import load_occupancy

        return load_occupancy(path, resolution, fallback_resolution, thresholds, memory_limit,
                              resolution_option)
    if suffix in CLOUD_SUFFIXES:
        from pcmapq.io.clouds import load_cloud

        return load_cloud(path, memory_limit)
    raise InputError(f"{path}: {unsupported(suffix)}")


def unsupported(suffix: str) -> str:
    """The problem of a file whose suffix no loader reads, naming every one that does."""
    return (f"unsupported format '{suffix}' (expected {', '.join(MAP_SUFFIXES)}, or "
            f"{BAG_FOLDER})")


def folder_problem(folder: Path) -> str:
    """Why a folder given as a map is not one: a folder of scans needs ``--scans`` (or
    ``pcmapq map`` to build its map); any other folder is not a map file."""
    scans = sum(1 for f in folder.iterdir() if f.is_file() and f.suffix.lower() in SCAN_SUFFIXES)
    if scans == 0 and (folder / "velodyne").is_dir():
        return folder_problem(folder / "velodyne")
    if scans:
        from pcmapq.core.words import count

        return (f"a folder of {count(scans, 'scan file')}, not a map: give it as --scans "
                f"FOLDER (eval, inspect), or build its map with 'pcmapq map {folder} --out "
                "map.ply'")
    return f"a folder, not a map file (expected a file: {', '.join(MAP_SUFFIXES)}; or " \
           f"{BAG_FOLDER})"
