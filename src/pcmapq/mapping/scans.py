"""Scan sequences: a folder of scan files, or a ROS bag / MCAP file.

A scan is ``(points, timestamps)``: points (N, 3) float64 metres in the sensor frame at that
scan, timestamps (N,) float64 per-point times (any unit and origin; KISS-ICP normalises them per
scan) or an empty array when the format has none (KITTI ``.bin``). Rows with a non-finite
coordinate are dropped.

- A folder of ``.bin`` (KITTI float32 x, y, z, reflectance), ``.ply``, ``.pcd`` or ``.npy``
  scans, in natural file-name order (``2.ply`` before ``10.ply``). A folder holding none but
  with a ``velodyne/`` sub-folder (the KITTI sequence layout) reads that sub-folder. PLY/PCD
  per-point times are taken from a field named t, timestamp, timestamps, time or stamps.
- A ROS 1 ``.bag``, a ROS 2 bag (a folder with ``metadata.yaml``, or its ``.db3``/``.mcap``) or
  a standalone ``.mcap``, read with rosbags (:mod:`pcmapq.io.bags`): ``sensor_msgs/PointCloud2``
  (with a per-point time field if it has one) or ``sensor_msgs/LaserScan`` messages; name the
  ``topic`` when there are several.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.io import pcd
from pcmapq.io.bag_scans import scan_topic
from pcmapq.io.bag_scans import scans as bag_scans
from pcmapq.io.bags import is_bag
from pcmapq.io.clouds import XYZ, read_kitti_bin, read_npy, with_z
from pcmapq.io.formats import SCAN_SUFFIXES
from pcmapq.io.writers import one_line

__all__ = ["SCAN_SUFFIXES", "ScanSequence", "open_scans"]


#: Per-point time fields of PLY/PCD scans, in the order KISS-ICP's generic loader tries them.
TIME_FIELDS = ("t", "timestamp", "timestamps", "time", "stamps")

Scan = tuple[np.ndarray, np.ndarray]


@dataclass(frozen=True)
class ScanSequence:
    """An ordered, finite sequence of scans; iterate it once per :func:`open_scans`.

    path: the source given. count: number of scans (after ``max_scans``). kind: "folder",
    "rosbag" or "mcap". files: the scan files of a folder (empty for bags); a bag's scan topic
    is kept as its ``_dataset``.
    """

    path: Path
    count: int
    kind: str
    files: tuple[Path, ...] = ()
    _dataset: Any = None

    def __len__(self) -> int:
        return self.count

    def __iter__(self) -> Iterator[Scan]:
        if self.kind == "folder":
            for file in self.files:
                yield read_scan(file)
            return
        for index, (_, points, stamps) in enumerate(bag_scans(self.path, self._dataset)):
            if index >= self.count:
                return
            yield _clean(self.path, points, stamps)


def open_scans(source: str | Path, *, max_scans: int | None = None, topic: str | None = None,
               ) -> ScanSequence:
    """Open a scan sequence (see the module docstring); ``max_scans`` keeps the first ones."""
    path = Path(source)
    if not path.exists():
        raise InputError(f"{path}: not found")
    if max_scans is not None and max_scans < 1:
        raise InputError(f"{path}: max_scans must be at least 1, got {max_scans}")
    if path.is_dir() and not (path / "metadata.yaml").exists():
        files = scan_files(path)
        if max_scans is not None:
            files = files[:max_scans]
        return ScanSequence(path, len(files), "folder", tuple(files))
    if is_bag(path):
        chosen = scan_topic(path, topic)
        count = chosen.count if max_scans is None else min(chosen.count, max_scans)
        kind = "mcap" if path.suffix.lower() == ".mcap" else "rosbag"
        return ScanSequence(path, count, kind, (), chosen.name)
    raise InputError(f"{path}: not a scan folder, .bag, ROS 2 bag or .mcap file")


def scan_files(folder: Path) -> list[Path]:
    """The scan files of a folder in natural name order (or of its ``velodyne/`` sub-folder)."""
    files = sorted((f for f in folder.iterdir()
                    if f.is_file() and f.suffix.lower() in SCAN_SUFFIXES), key=_natural_key)
    if not files and (folder / "velodyne").is_dir():
        return scan_files(folder / "velodyne")
    if not files:
        raise InputError(f"{folder}: no scan files ({', '.join(SCAN_SUFFIXES)})")
    suffixes = {f.suffix.lower() for f in files}
    if len(suffixes) > 1:
        raise InputError(f"{folder}: scan files of several formats ({', '.join(sorted(suffixes))})")
    return files


def read_scan(path: Path) -> Scan:
    """One scan file: points (N, 3) float64 metres, per-point timestamps (N,) or (0,)."""
    suffix = path.suffix.lower()
    try:
        if suffix == ".bin":
            return _clean(path, read_kitti_bin(path), np.empty(0))
        if suffix == ".npy":
            return _clean(path, with_z(path, read_npy(path)), np.empty(0))
        scan = _read_binary_pcd(path) if suffix == ".pcd" else None
        return _read_open3d_scan(path) if scan is None else scan
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {one_line(exc)}") from None


def _read_binary_pcd(path: Path) -> Scan | None:
    """A binary PCD's points and per-point times, as Open3D's tensor reader gives them
    (:func:`pcmapq.io.pcd.read_fields`); None for a PCD it does not read (Open3D does)."""
    table = pcd.read_fields(path, (*XYZ, *TIME_FIELDS))
    if table is None or not set(XYZ) <= table.keys():
        return None
    stamps = next((table[f] for f in TIME_FIELDS if f in table), np.empty(0))
    return _clean(path, np.column_stack([table[axis] for axis in XYZ]), stamps)


def _read_open3d_scan(path: Path) -> Scan:
    """PLY/PCD with Open3D's tensor reader, keeping a per-point time field if there is one."""
    import open3d as o3d  # heavy: loaded when a scan is not read without it

    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        cloud = o3d.t.io.read_point_cloud(str(path))
    if cloud.is_empty():
        raise InputError(f"{path}: no points (empty or unreadable)")
    points = cloud.point.positions.numpy()
    stamps = np.empty(0)
    for field in TIME_FIELDS:
        if field in cloud.point:
            stamps = cloud.point[field].numpy().reshape(-1)
            break
    return _clean(path, points, stamps)


def _clean(path: Path, points: np.ndarray, stamps: np.ndarray) -> Scan:
    """float64 copies; rows with a non-finite coordinate (or time) dropped."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    stamps = np.asarray(stamps, dtype=np.float64).reshape(-1)
    keep = np.isfinite(points).all(axis=1)
    if len(stamps) == len(points) and len(stamps):
        keep &= np.isfinite(stamps)
        return points[keep], stamps[keep]
    return points[keep], np.empty(0)


def _natural_key(path: Path) -> list[Any]:
    """Sort key: digit runs compare as numbers (``2.ply`` < ``10.ply``)."""
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", path.name)]
