"""A global map from a scan sequence and given poses (e.g. a reference map from ground truth).

``p_world = poses[k] @ calib @ p_sensor_k``: ``calib`` takes the scanner's frame to the frame the
poses describe (identity when None); metres. For KITTI see :mod:`pcmapq.mapping.poses`: either
``lidar_poses_from_camera(P, Tr)`` with ``calib=None`` (map in the first LiDAR frame, as
KISS-ICP's), or ``P`` with ``calib=Tr`` (map in the first camera frame).

The scans are used as read (no deskewing), cropped to ``[min_range, max_range]`` metres from the
scanner like KISS-ICP's input.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.transform import affine
from pcmapq.core.words import count
from pcmapq.mapping.scan_map import ScanGrid, ScanMap
from pcmapq.mapping.scans import ScanSequence, open_scans
from pcmapq.metrics.posed import place

__all__ = ["build_map_from_poses", "describe_scans", "scans_for_poses"]


def scans_for_poses(source: str | Path | ScanSequence, pose_count: int, *,
                    max_scans: int | None = None, topic: str | None = None,
                    poses_path: Path | str | None = None) -> ScanSequence:
    """The scans ``pose_count`` poses place: every scan of the sequence, which must have one
    pose each, or its first ``max_scans`` (the poses must cover them). Otherwise InputError,
    one line naming the poses file (``poses_path``) and the counts."""
    scans = source if isinstance(source, ScanSequence) else open_scans(source, topic=topic)
    name = "poses" if poses_path is None else str(poses_path)
    if max_scans is None:
        if pose_count != len(scans):
            raise InputError(f"{name}: {count(pose_count, 'pose')} for "
                             f"{count(len(scans), 'scan')} in "
                             f"{scans.path} (one pose per scan); --max-scans "
                             f"{min(pose_count, len(scans))} maps the first "
                             f"{min(pose_count, len(scans))}")
        return scans
    wanted = min(max_scans, len(scans))
    if pose_count < wanted:
        raise InputError(f"{name}: {count(pose_count, 'pose')} for the first "
                         f"{count(wanted, 'scan')} of "
                         f"{scans.path}")
    return replace(scans, count=wanted, files=scans.files[:wanted])


def describe_scans(scans: ScanSequence, total: int) -> str:
    """Which scans a sequence holds, in words: ``scans 000000.bin to 000004.bin (the first 5
    of 20) of DIR``; messages of a bag count from 0."""
    first, last = (scans.files[0].name, scans.files[-1].name) if scans.files else (
        "0", str(len(scans) - 1))
    return (f"scans {first} to {last} (the first {len(scans)} of {total}) of {scans.path}")


def build_map_from_poses(source: str | Path | ScanSequence, poses: np.ndarray,
                         calib: np.ndarray | None = None, *, max_scans: int | None = None,
                         voxel: float = 0.1, progress: Callable[[int, int], None] | None = None,
                         min_range: float = 0.0, max_range: float = 100.0,
                         topic: str | None = None) -> ScanMap:
    """Accumulate scan k placed by ``poses[k] @ calib`` into one map.

    source: a scan folder, ROS bag or MCAP file, or a sequence opened already. poses: (K, 4,
    4), one per scan in order; the scans used are all of them (K must equal their number) or
    the first ``max_scans`` (K at least that; see :func:`scans_for_poses`). calib: 4x4
    scanner -> pose frame, or None. voxel: output cell, metres. progress: ``progress(done,
    total)`` after each scan.

    Returns the map: its points (N, 3) float64, metres, in the poses' world frame, and each
    one's scan (:mod:`pcmapq.mapping.scan_map`). Deterministic.
    """
    poses = np.asarray(poses, dtype=np.float64)
    if poses.ndim != 3 or poses.shape[1:] != (4, 4) or len(poses) == 0:
        raise InputError(f"poses: expected K x 4 x 4, got shape {poses.shape}")
    scans = scans_for_poses(source, len(poses), max_scans=max_scans, topic=topic)
    mount = np.eye(4) if calib is None else np.asarray(calib, dtype=np.float64).reshape(4, 4)
    grid = ScanGrid(voxel)
    for index, (points, _) in enumerate(scans):
        ranges = np.linalg.norm(points, axis=1)
        points = points[(ranges >= min_range) & (ranges <= max_range)]
        place = poses[index] @ mount
        grid.add(affine(points, place), index)
        if progress is not None:
            progress(index + 1, len(scans))
    return grid.map()


def posed_map(source: str | Path | ScanSequence, poses: np.ndarray, *,
              max_scans: int | None = None) -> np.ndarray:
    """Every scan placed at its pose relative to the first, as map-metrics' ``aggregate_map``
    (no voxel, no range limit): the map (N, 3) float64, metres, in the first scan's frame.
    ``poses``: (K, 4, 4), one per scan (see :func:`scans_for_poses`)."""
    scans = scans_for_poses(source, len(poses), max_scans=max_scans)
    return place([points for points, _ in scans], list(poses[:len(scans)]))
