"""Similarity2D: ``p_truth = s * R(yaw) * p_map + t``, the one frame convention of pcmapq."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def affine(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Points (N, d) through the homogeneous (d + 1, d + 1) ``matrix``: the same numbers as
    ``points @ matrix[:d, :d].T + matrix[:d, d]``, with the rotation made contiguous first
    (NumPy multiplies by a strided view outside BLAS, far more slowly)."""
    d = points.shape[1]
    out = points @ np.ascontiguousarray(matrix[:d, :d].T)
    out += matrix[:d, d]  # in place: no second array of all the points
    return out


@dataclass(frozen=True)
class Similarity2D:
    """A 2D similarity taking map-frame points to the truth frame.

    scale: dimensionless; yaw: radians; tx, ty: metres.
    """

    tx: float = 0.0
    ty: float = 0.0
    yaw: float = 0.0
    scale: float = 1.0

    @property
    def matrix(self) -> np.ndarray:
        """3x3 homogeneous matrix, map frame -> truth frame."""
        c, s = np.cos(self.yaw) * self.scale, np.sin(self.yaw) * self.scale
        return np.array([[c, -s, self.tx], [s, c, self.ty], [0.0, 0.0, 1.0]])

    @classmethod
    def from_matrix(cls, m: np.ndarray) -> Similarity2D:
        """From a 3x3 (or the top-left 2x3 of a 4x4 planar) similarity matrix."""
        m = np.asarray(m, dtype=np.float64)
        if m.shape == (4, 4):
            m = np.array([[m[0, 0], m[0, 1], m[0, 3]], [m[1, 0], m[1, 1], m[1, 3]], [0, 0, 1.0]])
        scale = float(np.hypot(m[0, 0], m[1, 0]))
        yaw = float(np.arctan2(m[1, 0], m[0, 0]))
        return cls(float(m[0, 2]), float(m[1, 2]), yaw, scale)

    def apply(self, xy: np.ndarray) -> np.ndarray:
        """Map-frame (N, 2) metres -> truth-frame (N, 2) metres."""
        return affine(np.asarray(xy, dtype=np.float64).reshape(-1, 2), self.matrix)

    def inverse(self) -> Similarity2D:
        return Similarity2D.from_matrix(np.linalg.inv(self.matrix))

    def compose(self, first: Similarity2D) -> Similarity2D:
        """The transform that applies ``first``, then ``self``."""
        return Similarity2D.from_matrix(self.matrix @ first.matrix)

    def to_dict(self) -> dict[str, float]:
        """``{"x_m", "y_m", "yaw_deg", "scale"}``: the form every saved transform takes."""
        return {"x_m": self.tx, "y_m": self.ty, "yaw_deg": self.yaw_deg, "scale": self.scale}

    @classmethod
    def from_dict(cls, doc: dict) -> Similarity2D:
        """The inverse of :meth:`to_dict`."""
        return cls(doc["x_m"], doc["y_m"], float(np.radians(doc["yaw_deg"])), doc["scale"])

    @property
    def yaw_deg(self) -> float:
        """Yaw in degrees, wrapped to (-180, 180]."""
        deg = float(np.degrees(self.yaw))
        return 180.0 - (180.0 - deg) % 360.0


def wrapped(angle: np.ndarray | float) -> np.ndarray | float:
    """Angles (radians) wrapped to (-pi, pi]: the turn between two yaws is
    ``wrapped(a - b)``."""
    return np.angle(np.exp(1j * np.asarray(angle)))
