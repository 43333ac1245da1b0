"""MetricGrid: the one type that ties grid cells to metres.

A grid follows the ROS map_server convention: ``origin = (x, y, yaw)`` is the pose, in the grid's
metric frame, of the lower-left corner of the image (the outer corner of cell ``(rows - 1, 0)``).
Row 0 is the top row of the image. Pixel coordinates follow OpenCV: ``u`` = column, ``v`` = row,
with cell centres at integer values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.core.bounds import bounds
from pcmapq.core.transform import affine


@dataclass(frozen=True)
class MetricGrid:
    """A raster in a metric frame.

    resolution: cell size in metres.
    origin: (x, y, yaw) of the image's lower-left corner; metres, metres, radians.
    shape: (rows, cols).
    """

    resolution: float
    origin: tuple[float, float, float]
    shape: tuple[int, int]

    def pixel_to_xy_matrix(self) -> np.ndarray:
        """3x3 homogeneous matrix taking pixel (u, v, 1) to metric (x, y, 1)."""
        res = self.resolution
        rows = self.shape[0]
        local = np.array([[res, 0.0, 0.5 * res], [0.0, -res, (rows - 0.5) * res], [0.0, 0.0, 1.0]])
        c, s = np.cos(self.origin[2]), np.sin(self.origin[2])
        pose = np.array([[c, -s, self.origin[0]], [s, c, self.origin[1]], [0.0, 0.0, 1.0]])
        return pose @ local

    def xy_to_pixel_matrix(self) -> np.ndarray:
        """3x3 homogeneous matrix taking metric (x, y, 1) to pixel (u, v, 1)."""
        return np.linalg.inv(self.pixel_to_xy_matrix())

    def pixels_to_xy(self, uv: np.ndarray) -> np.ndarray:
        """(N, 2) pixel coordinates (u = column, v = row) -> (N, 2) metric x, y in metres."""
        return affine(np.asarray(uv, dtype=np.float64).reshape(-1, 2), self.pixel_to_xy_matrix())

    def xy_to_pixels(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) metric x, y in metres -> (N, 2) float pixel coordinates (u, v)."""
        return affine(np.asarray(xy, dtype=np.float64).reshape(-1, 2), self.xy_to_pixel_matrix())

    def cell_centres(self, mask: np.ndarray) -> np.ndarray:
        """Metric (x, y) of the centres of the cells where ``mask`` is true, (N, 2) metres."""
        v, u = np.nonzero(mask)
        return self.pixels_to_xy(np.column_stack([u, v]))

    @property
    def size_m(self) -> tuple[float, float]:
        """Extent (width, height) in metres."""
        return self.shape[1] * self.resolution, self.shape[0] * self.resolution

    def resampled(self, resolution: float) -> MetricGrid:
        """The grid covering the same area (same origin and yaw) at another cell size, metres."""
        width, height = self.size_m
        shape = (max(1, int(np.ceil(height / resolution - 1e-9))),
                 max(1, int(np.ceil(width / resolution - 1e-9))))
        return MetricGrid(resolution, self.origin, shape)

    @classmethod
    def covering(cls, xy: np.ndarray, resolution: float, margin: float = 1.0) -> MetricGrid:
        """An axis-aligned grid (yaw 0) that covers points ``xy`` (N, 2, metres) plus a margin."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        low, high = bounds(xy)
        lo = np.floor((low - margin) / resolution) * resolution
        hi = high + margin
        cols, rows = np.ceil((hi - lo) / resolution).astype(int) + 1
        return cls(float(resolution), (float(lo[0]), float(lo[1]), 0.0), (int(rows), int(cols)))
