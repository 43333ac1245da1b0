"""Known poses for alignment tests: how far a found 2D pose is from the known one, and 4x4
rigid transforms of 3D points (made from a rotation vector, applied, compared)."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from pcmapq.core.transform import Similarity2D, affine


def pose_error(expected: Similarity2D, got: Similarity2D) -> tuple[float, float]:
    """(translation error in metres, yaw error in degrees)."""
    dyaw = abs((np.degrees(got.yaw - expected.yaw) + 180.0) % 360.0 - 180.0)
    return float(np.hypot(got.tx - expected.tx, got.ty - expected.ty)), float(dyaw)


def rigid(rotvec_deg: tuple[float, float, float], offset: tuple[float, float, float]
          ) -> np.ndarray:
    """The 4x4 rigid transform turning by a rotation vector (degrees), then moving by
    ``offset`` (metres)."""
    out = np.eye(4)
    out[:3, :3] = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    out[:3, 3] = offset
    return out


def apply(transform: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``points`` (N, 3) moved by a 4x4 transform."""
    return affine(points, transform)


def errors(estimate: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """(translation error m, rotation error deg) of ``inv(truth) @ estimate``."""
    delta = np.linalg.inv(truth) @ estimate
    cos = np.clip((np.trace(delta[:3, :3]) - 1) / 2, -1.0, 1.0)
    return float(np.linalg.norm(delta[:3, 3])), float(np.degrees(np.arccos(cos)))


def rotation_about(axis: np.ndarray, degrees: float) -> np.ndarray:
    """3x3 rotation about a unit axis."""
    import open3d as o3d

    return o3d.geometry.get_rotation_matrix_from_axis_angle(
        np.asarray(axis, dtype=np.float64) * np.radians(degrees))
