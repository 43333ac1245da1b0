"""The LiDAR front end: maps from scan sequences, with KISS-ICP or with given poses.

- :func:`build_map_kiss`: KISS-ICP odometry over the scans, deskewed scans accumulated.
- :func:`build_map_from_poses`: the scans placed with known poses (a reference map).
- :class:`ScanMap`: a built map's points and the scans each came from.
- :func:`posed_map`: the scans placed relative to the first pose, as map-metrics places them.
- :mod:`pcmapq.mapping.poses`: KITTI / TUM pose files and calibrations.

Frames: ``p_world = pose_k @ calib @ p_sensor``; every length in metres.
"""

from __future__ import annotations

from pcmapq.core.voxels import VoxelMap, voxel_centroids
from pcmapq.mapping.kiss import build_map_kiss, kiss_config
from pcmapq.mapping.poses import (
    lidar_poses_from_camera,
    moves_along_z,
    read_calib,
    read_kitti_poses,
    read_pose_matrix,
    read_poses,
    read_tum_poses,
    recorded_poses,
    scanner_poses,
    write_kitti_poses,
    write_tum_poses,
)
from pcmapq.mapping.reference import (
    build_map_from_poses,
    describe_scans,
    posed_map,
    scans_for_poses,
)
from pcmapq.mapping.scan_map import ScanGrid, ScanMap
from pcmapq.mapping.scans import ScanSequence, open_scans

__all__ = [
    "ScanGrid",
    "ScanMap",
    "ScanSequence",
    "VoxelMap",
    "build_map_from_poses",
    "build_map_kiss",
    "describe_scans",
    "kiss_config",
    "lidar_poses_from_camera",
    "moves_along_z",
    "open_scans",
    "posed_map",
    "read_calib",
    "read_kitti_poses",
    "read_pose_matrix",
    "read_poses",
    "read_tum_poses",
    "recorded_poses",
    "scanner_poses",
    "scans_for_poses",
    "voxel_centroids",
    "write_kitti_poses",
    "write_tum_poses",
]
