"""KITTI odometry sequence 00's calibration (its velodyne -> left camera transform) and a pitch
drift of its scans' poses."""

from __future__ import annotations

import numpy as np

#: Velodyne -> left camera of KITTI odometry sequence 00 (calib.txt, ``Tr:``), row-major 3x4.
TR_00 = (
    "4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
    "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
    "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01"
)


def tr_00() -> np.ndarray:
    """TR_00 as a 4x4 matrix."""
    tr = np.eye(4)
    tr[:3, :4] = np.array(TR_00.split(), dtype=np.float64).reshape(3, 4)
    return tr


def pitched(poses: np.ndarray, level_deg: float) -> np.ndarray:
    """LiDAR poses (K, 4, 4) with scan k's turned ``k * level_deg`` degrees about its lateral
    axis (the velodyne's y: it looks along x, y to its left, z up): a pitch drift growing scan
    by scan, the first scan where it was."""
    angle = np.radians(level_deg * np.arange(len(poses)))
    turn = np.tile(np.eye(4), (len(poses), 1, 1))
    turn[:, 0, 0] = turn[:, 2, 2] = np.cos(angle)
    turn[:, 0, 2], turn[:, 2, 0] = np.sin(angle), -np.sin(angle)
    return poses @ turn
