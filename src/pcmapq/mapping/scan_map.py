"""A map built from scans: voxel centroids, each with the scans it came from.

The scan of a point is the mean index of the scans whose points its voxel holds (0: the first
scan; a voxel seen by scans 3 and 4 alike is 3.5): a map's points carry where along the run
they were seen, which :mod:`pcmapq.align.stretches` cuts into stretches of the run. ``pcmapq
map`` writes it as the vertex property ``scan`` (float) of a PLY or the field ``scan`` of a
PCD.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.core.voxels import VoxelMap

__all__ = ["ScanGrid", "ScanMap"]


@dataclass(frozen=True)
class ScanMap:
    """points: (N, 3) float64 voxel centroids, metres (the map's frame). scan: (N,) float64,
    each one's mean scan index (the module's docstring)."""

    points: np.ndarray
    scan: np.ndarray

    def __len__(self) -> int:
        return len(self.points)


class ScanGrid:
    """Scans accumulated into voxel centroids of ``voxel`` metres, each voxel averaging the
    indices of the scans that put points in it."""

    def __init__(self, voxel: float) -> None:
        self._grid = VoxelMap(voxel, carried=1)

    def add(self, points: np.ndarray, index: int) -> None:
        """Add scan ``index``'s points (N, 3, metres, the map's frame)."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        self._grid.add(np.column_stack([points, np.full(len(points), float(index))]))

    def map(self) -> ScanMap:
        """The map so far."""
        table = self._grid.points()
        return ScanMap(np.ascontiguousarray(table[:, :3]), table[:, 3].copy())
