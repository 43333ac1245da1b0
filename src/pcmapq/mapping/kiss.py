"""A global map from a scan sequence with KISS-ICP (LiDAR odometry, no loop closure).

KISS-ICP keeps only a local map around the sensor. Each scan goes through
``KissICP.register_frame``, which returns the scan deskewed (motion compensated, range cropped)
in the sensor frame; it is placed in the world with the pose KISS-ICP estimated for it and
accumulated into a :class:`~pcmapq.core.voxels.VoxelMap`.

Frames: the world frame is the sensor frame of the first scan (its pose is the identity);
``p_world = poses[k] @ p_sensor_k``; metres.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.mapping.scan_map import ScanGrid, ScanMap
from pcmapq.mapping.scans import open_scans

if TYPE_CHECKING:
    from kiss_icp.config import KISSConfig

__all__ = ["build_map_kiss", "kiss_config"]

Progress = Callable[[int, int], None]


def kiss_config(*, max_range: float = 100.0, min_range: float = 0.0, deskew: bool = True,
                kiss_voxel: float | None = None, threads: int = 0) -> KISSConfig:
    """A KISS-ICP configuration with KISS-ICP's defaults unless told.

    max_range, min_range: points kept, metres from the sensor. kiss_voxel: voxel of KISS-ICP's
    local map, metres (default ``max_range / 100``, as KISS-ICP does). threads: KISS-ICP's
    threads (0: all cores). Runs agree to about 1e-12 m, not bit for bit, whatever the thread
    count (KISS-ICP's C++ reductions sum in an order that varies).
    """
    from kiss_icp.config import KISSConfig  # loaded when KISS-ICP runs (it loads pydantic)

    config = KISSConfig()
    config.data.max_range = float(max_range)
    config.data.min_range = float(min_range)
    config.data.deskew = bool(deskew)
    config.mapping.voxel_size = float(kiss_voxel if kiss_voxel else max_range / 100.0)
    config.registration.max_num_threads = int(threads)
    return config


def build_map_kiss(source: str | Path, *, max_scans: int | None = None, voxel: float = 0.1,
                   progress: Progress | None = None, config: KISSConfig | None = None,
                   topic: str | None = None) -> tuple[ScanMap, np.ndarray]:
    """Run KISS-ICP over a scan sequence and accumulate its deskewed scans into one map.

    source: a scan folder, ROS bag or MCAP file (see :mod:`pcmapq.mapping.scans`).
    max_scans: use only the first scans. voxel: cell of the output map, metres (one centroid per
    cell). progress: called as ``progress(done, total)`` after each scan. config: KISS-ICP
    settings (default :func:`kiss_config`). topic: the PointCloud2 topic of a bag.

    Returns ``(map, poses)``: the map's points (N, 3) float64 with each one's scan
    (:mod:`pcmapq.mapping.scan_map`) and poses (K, 4, 4) float64 (sensor at scan k -> world),
    both in the first scan's sensor frame, metres. Repeatable to ~1e-12 m
    (see :func:`kiss_config`).
    """
    from kiss_icp.kiss_icp import KissICP

    scans = open_scans(source, max_scans=max_scans, topic=topic)
    odometry = KissICP(config=config or kiss_config())
    grid = ScanGrid(voxel)
    poses: list[np.ndarray] = []
    for index, (points, stamps) in enumerate(scans):
        if len(points) == 0:
            raise InputError(f"{scans.path}: scan {index} has no points")
        deskewed, _ = odometry.register_frame(points, stamps)
        pose = np.array(odometry.last_pose, dtype=np.float64)
        poses.append(pose)
        grid.add(np.asarray(deskewed) @ pose[:3, :3].T + pose[:3, 3], index)
        if progress is not None:
            progress(index + 1, len(scans))
    if not poses:
        raise InputError(f"{scans.path}: no scans")
    return grid.map(), np.stack(poses)
