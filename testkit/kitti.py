"""KITTI odometry sequence 00's calibration: its velodyne -> left camera transform."""

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
