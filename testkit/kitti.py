"""KITTI odometry sequence 00: its velodyne -> left camera transform, a pitch drift of its
scans' poses (:func:`pitched`), drifts that integrate along the run as odometry's do
(:func:`curved`, :func:`stretched`), and maps of its first scans at the reference poses and at
poses that drift in pitch (:func:`pitch_ladder`)."""

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


def pitch_ladder(steps_deg: tuple[float, ...], voxel: float = 0.1
                 ) -> tuple[np.ndarray, dict[float, np.ndarray]]:
    """KITTI 00's scans (../shared/data/kitti00) placed at its reference LiDAR poses, the truth
    map, and for each step of ``steps_deg`` a drifted map: scan k's pose pitched by k times the
    step, degrees, about the scanner's own lateral (y) axis, so its far points rise or sink
    more with every scan. Maps (N, 3), metres, voxel centroids of ``voxel`` metres, in the
    first scan's frame."""
    from pcmapq.mapping import build_map_from_poses, lidar_poses_from_camera, read_kitti_poses

    from .paths import shared

    folder = shared("kitti00")
    poses = lidar_poses_from_camera(read_kitti_poses(folder / "poses.txt"), tr_00())
    truth = build_map_from_poses(folder, poses, voxel=voxel).points
    drifted = {step: build_map_from_poses(folder, pitched(poses, step), voxel=voxel).points
               for step in steps_deg}
    return truth, drifted


def pitched(poses: np.ndarray, level_deg: float) -> np.ndarray:
    """LiDAR poses (K, 4, 4) with scan k's turned ``k * level_deg`` degrees about its lateral
    axis (the velodyne's y: it looks along x, y to its left, z up): a pitch drift growing scan
    by scan, the first scan where it was."""
    angle = np.radians(level_deg * np.arange(len(poses)))
    turn = np.tile(np.eye(4), (len(poses), 1, 1))
    turn[:, 0, 0] = turn[:, 2, 2] = np.cos(angle)
    turn[:, 0, 2], turn[:, 2, 0] = np.sin(angle), -np.sin(angle)
    return poses @ turn


def turn(axis: str, degrees: float) -> np.ndarray:
    """4x4 turn of ``degrees`` about the frame's own ``axis`` ("x", "y" or "z"), right-handed
    (about z: +x towards +y; about y: +x down, as :func:`pitched`)."""
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    a = np.radians(degrees)
    out = np.eye(4)
    out[i, i] = out[j, j] = np.cos(a)
    out[j, i], out[i, j] = np.sin(a), -np.sin(a)
    return out


def curved(poses: np.ndarray, axis: str, level_deg: float) -> np.ndarray:
    """LiDAR poses (K, 4, 4) drifting as odometry that misreads every turn: each step's motion
    (pose k-1 -> k) turned a further ``level_deg`` degrees about the scanner's own ``axis``
    ("z": heading, the run curves sideways; "y": pitch, it bends down), so scan k is turned
    k x ``level_deg`` and its position follows the bent run; the first scan where it was."""
    step = turn(axis, level_deg)
    motion = np.linalg.inv(poses[:-1]) @ poses[1:]
    out = [np.asarray(poses[0], dtype=np.float64)]
    for move in motion:  # one product per scan, integrated in order
        out.append(out[-1] @ step @ move)
    return np.array(out)


def stretched(poses: np.ndarray, share: float) -> np.ndarray:
    """LiDAR poses (K, 4, 4) drifting as odometry whose every step is ``share`` too long:
    scan k at first + (1 + share) (p_k - first), metres, its orientation kept."""
    out = np.array(poses, dtype=np.float64)
    out[:, :3, 3] = out[0, :3, 3] + (1.0 + share) * (out[:, :3, 3] - out[0, :3, 3])
    return out
