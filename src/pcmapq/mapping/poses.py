"""Pose files: KITTI and TUM trajectories, and sensor calibrations.

A pose is a 4x4 homogeneous matrix ``P_k`` taking points of the sensor frame at scan ``k`` to
the world frame, ``p_world = P_k @ p_sensor``; translations in metres.

- KITTI: one pose per line, 12 numbers, the top 3x4 of ``P_k`` in row-major order.
- TUM: one pose per line, ``t x y z qx qy qz qw`` (seconds, metres, unit quaternion with the
  scalar last).
- A folder of pose files, one per scan in name order, each the 4x4 matrix ``P_k`` (or its top
  3x4) as four (three) rows of numbers: map-metrics' layout.

Both are written with single spaces, no header and full float precision, as ``evo`` reads them.
Lines that are empty or start with ``#`` are skipped when reading.

KITTI's odometry ground truth (``poses/NN.txt``) is the pose of the **left camera**; its Velodyne
scans are in the LiDAR frame, linked by the calibration ``Tr`` (LiDAR -> camera, ``Tr:`` in
``calib.txt``). Two equivalent ways to place LiDAR scans with these poses:

- :func:`lidar_poses_from_camera` ``(P, Tr)`` = ``inv(Tr) @ P @ Tr``: LiDAR poses in the first
  LiDAR frame (x forward, z up), the frame KISS-ICP's map is in; use with ``calib=None``;
- ``P`` with ``calib=Tr`` in :func:`pcmapq.mapping.build_map_from_poses`: the map in the first
  camera frame (z forward, y down).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.io.writers import OutputSet, one_line, write_atomic

__all__ = [
    "lidar_poses_from_camera",
    "moves_along_z",
    "read_calib",
    "read_kitti_poses",
    "read_pose_matrix",
    "read_poses",
    "read_tum_poses",
    "scanner_poses",
    "write_kitti_poses",
    "write_tum_poses",
]

#: Largest departure of a pose's last row from (0, 0, 0, 1), and of a rotation from orthonormal.
_TOLERANCE = 1e-6

#: Keys of a LiDAR -> camera transform in KITTI calibration files.
_CALIB_KEYS = ("Tr", "Tr_velo_to_cam", "Tr_velo_cam")


def read_kitti_poses(path: str | Path) -> np.ndarray:
    """Read a KITTI pose file: (K, 4, 4) float64 poses, sensor -> world, metres."""
    path = Path(path)
    table = _read_table(path, 12, "12 numbers (row-major 3x4 pose)")
    return _homogeneous(table.reshape(-1, 3, 4))


def write_kitti_poses(path: str | Path, poses: np.ndarray,
                      outputs: OutputSet | None = None) -> None:
    """Write poses (K, 4, 4), sensor -> world, metres, as a KITTI pose file (atomically; with
    ``outputs``, when that set is committed).

    Numbers are written with ``repr`` precision, so reading the file back gives the same floats.
    """
    poses = _check_poses(np.asarray(poses, dtype=np.float64), Path(path))
    rows = poses[:, :3, :].reshape(-1, 12)
    write_atomic(Path(path), _format_rows(rows), outputs)


def read_tum_poses(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read a TUM trajectory: timestamps (K,) seconds and poses (K, 4, 4), sensor -> world.

    Quaternions are normalised; a zero quaternion is an error.
    """
    path = Path(path)
    table = _read_table(path, 8, "8 numbers (t x y z qx qy qz qw)")
    quats = table[:, 4:8]
    norms = np.linalg.norm(quats, axis=1)
    if np.any(norms < 1e-9):
        line = int(np.argmax(norms < 1e-9)) + 1
        raise InputError(f"{path}: pose {line} has a zero quaternion")
    poses = np.tile(np.eye(4), (len(table), 1, 1))
    poses[:, :3, :3] = Rotation.from_quat(quats / norms[:, None]).as_matrix()
    poses[:, :3, 3] = table[:, 1:4]
    return table[:, 0].copy(), poses


def write_tum_poses(path: str | Path, poses: np.ndarray, timestamps: np.ndarray | None = None,
                    outputs: OutputSet | None = None) -> None:
    """Write poses (K, 4, 4), sensor -> world, as a TUM trajectory (atomically; with
    ``outputs``, when that set is committed).

    ``timestamps`` (K,) in seconds; default 0, 1, 2, ... (the scan index). The rotation written
    is the nearest rotation to ``poses[:, :3, :3]``, as a unit quaternion with ``qw >= 0``.
    Timestamps and translations read back exactly; rotations to about 1e-15.
    """
    path = Path(path)
    poses = _check_poses(np.asarray(poses, dtype=np.float64), path)
    stamps = (np.arange(len(poses), dtype=np.float64) if timestamps is None
              else np.asarray(timestamps, dtype=np.float64).reshape(-1))
    if len(stamps) != len(poses):
        raise InputError(f"{path}: {count(len(stamps), 'timestamp')} for "
                         f"{count(len(poses), 'pose')}")
    quats = Rotation.from_matrix(poses[:, :3, :3]).as_quat()  # x, y, z, w
    quats *= np.where(quats[:, 3:4] < 0, -1.0, 1.0)
    rows = np.column_stack([stamps, poses[:, :3, 3], quats])
    write_atomic(path, _format_rows(rows), outputs)


def read_pose_matrix(path: str | Path) -> np.ndarray:
    """One pose from a text file of four rows of four numbers (or the top three): 4x4, sensor ->
    world, metres."""
    path = Path(path)
    rows = _read_table(path, 4, "4 numbers (a row of a 4x4 pose)")
    if len(rows) == 3:
        rows = np.vstack([rows, [0.0, 0.0, 0.0, 1.0]])
    if len(rows) != 4:
        raise InputError(f"{path}: {count(len(rows), 'row')}, expected a 4x4 pose")
    return _check_poses(rows[None], path)[0]


def read_poses(path: str | Path) -> np.ndarray:
    """Read a KITTI (12 columns) or TUM (8 columns) pose file, told apart by its first data
    line, or a folder of 4x4 pose files (name order): (K, 4, 4) poses, sensor -> world,
    metres."""
    path = Path(path)
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.is_file() and not p.name.startswith("."))
        if not files:
            raise InputError(f"{path}: no pose files in the folder")
        return np.stack([read_pose_matrix(f) for f in files])
    lines = [ln for ln in _read_text(path).splitlines() if ln.strip() and not ln.startswith("#")]
    if lines and len(lines[0].split()) == 8:
        return read_tum_poses(path)[1]
    return read_kitti_poses(path)


def read_calib(path: str | Path) -> np.ndarray:
    """Read a sensor calibration as a 4x4 transform (sensor -> frame of the poses, metres).

    Accepted: a file of exactly 12 numbers (row-major 3x4) or 16 numbers (row-major 4x4), over
    any number of lines; or a KITTI ``calib.txt`` (``key: numbers`` lines) with a ``Tr:`` line
    (also ``Tr_velo_to_cam:``), the Velodyne -> left camera transform.
    """
    path = Path(path)
    text = _read_text(path)
    keyed = _keyed_lines(text)
    if keyed:
        for key in _CALIB_KEYS:
            if key in keyed:
                values = _numbers(keyed[key], path, f"'{key}:'")
                if len(values) != 12:
                    raise InputError(f"{path}: '{key}:' has {count(len(values), 'number')}, "
                                     "expected 12")
                return _homogeneous(values.reshape(1, 3, 4))[0]
        raise InputError(f"{path}: no 'Tr:' line (keys: {', '.join(sorted(keyed))})")
    body = " ".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))
    values = _numbers(body, path, "calibration")
    if len(values) == 12:
        return _homogeneous(values.reshape(1, 3, 4))[0]
    if len(values) == 16:
        return _check_poses(values.reshape(1, 4, 4), path)[0]
    raise InputError(f"{path}: {count(len(values), 'number')}, expected 12 (3x4) or 16 (4x4) "
                     "or a KITTI calib.txt with a 'Tr:' line")


def lidar_poses_from_camera(camera_poses: np.ndarray, tr: np.ndarray) -> np.ndarray:
    """KITTI camera poses -> LiDAR poses: ``inv(Tr) @ P_k @ Tr`` for each ``k``.

    camera_poses: (K, 4, 4) left-camera poses (camera_k -> camera_0), as in KITTI's
    ``poses/NN.txt``. tr: 4x4 LiDAR -> camera transform (``Tr`` of ``calib.txt``).
    Returns (K, 4, 4) LiDAR poses (lidar_k -> lidar_0), for scans placed with ``calib=None``.
    """
    tr = np.asarray(tr, dtype=np.float64).reshape(4, 4)
    return np.linalg.inv(tr) @ np.asarray(camera_poses, dtype=np.float64) @ tr


def moves_along_z(poses: np.ndarray, min_travel: float = 0.5) -> bool:
    """Whether a trajectory (K, 4, 4) moves mostly along its first pose's z axis, by more than
    ``min_travel`` metres: a camera's forward axis (KITTI's reference poses are the left
    camera's: x right, y down, z forward), not a scanner's or a robot's up axis (REP 103: x
    forward, z up). The test is on the pose furthest from the first: |dz| > |d| / sqrt(2)."""
    poses = np.asarray(poses, dtype=np.float64)
    steps = (poses[:, :3, 3] - poses[0, :3, 3]) @ poses[0, :3, :3]  # in the first pose's frame
    far = steps[int(np.argmax(np.linalg.norm(steps, axis=1)))]
    travel = float(np.linalg.norm(far))
    return travel > min_travel and abs(far[2]) > travel / np.sqrt(2.0)


def scanner_poses(path: str | Path, calib: str | Path | None = None) -> np.ndarray:
    """The scanner's poses (K, 4, 4) from a KITTI or TUM file: as written, or, with ``calib``
    (a file :func:`read_calib` reads: T, the scanner -> pose-frame transform), moved into the
    scanner's frame, ``inv(T) @ P_k @ T`` (:func:`lidar_poses_from_camera`). Without
    ``calib``, poses that move along their z axis as a camera's do (:func:`moves_along_z`)
    get one warning naming the file: taken as the scanner's, a map built on them smears and
    pose errors are the camera's."""
    poses = read_poses(path)
    if calib is not None:
        return lidar_poses_from_camera(poses, read_calib(calib))
    if moves_along_z(poses):
        warnings.warn(f"{path}: these poses move along their z axis, as a camera's do (KITTI's "
                      "are the left camera's); without --calib (KITTI's Tr) they are taken as "
                      "the scanner's: a map built on them smears and pose errors are the "
                      "camera's", stacklevel=2)
    return poses


def recorded_poses(source: str | Path, scan_topic: str | None, pose_topic: str,
                   calib: str | Path | None = None, frame: str | None = None) -> np.ndarray:
    """One pose per scan of a recording (K, 4, 4): its pose topic interpolated at the scans'
    times, or with ``pose_topic`` a tf topic (``/tf``), the pose of ``frame`` (default: the
    scans' own frame) in the transform tree's root; with ``calib`` (T, scanner -> pose
    frame) the scanner's, ``P_k @ T``. Scans far in time from the poses are warned about or
    refused (:func:`pcmapq.io.bag_scans.check_gaps`)."""
    from pcmapq.io.bag_scans import (
        check_gaps,
        pose_gaps,
        pose_track,
        poses_at,
        scan_frame,
        scan_times,
    )
    from pcmapq.io.bag_tf import TF_TYPES, frame_poses
    from pcmapq.io.bags import is_bag, opened, topics

    source, calib = Path(source), None if calib is None else Path(calib)
    if not is_bag(source):
        raise InputError(f"{source}: --pose-topic reads the poses of a ROS recording")
    times = scan_times(source, scan_topic)
    with opened(source) as reader:
        kinds = {t.name: t.msgtype for t in topics(reader)}
    if kinds.get(pose_topic) in TF_TYPES:
        trajectory = frame_poses(source, frame or scan_frame(source, scan_topic), times)
    else:
        track_times, track = pose_track(source, pose_topic)
        check_gaps(source, pose_topic, times, pose_gaps(times, track_times))
        trajectory = poses_at(times, track_times, track)
    return trajectory if calib is None else trajectory @ read_calib(calib)


# ---------------------------------------------------------------------------------------------

def _read_text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {one_line(exc)}") from None


def _read_table(path: Path, columns: int, expected: str) -> np.ndarray:
    """The numbers of a whitespace-separated text file, (K, columns) float64; comments skipped."""
    rows: list[np.ndarray] = []
    for number, line in enumerate(_read_text(path).splitlines(), start=1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        values = _numbers(line, path, f"line {number}")
        if len(values) != columns:
            raise InputError(f"{path}: line {number} has {count(len(values), 'number')}, "
                             f"expected {expected}")
        rows.append(values)
    if not rows:
        raise InputError(f"{path}: no poses")
    return np.vstack(rows)


def _numbers(text: str, path: Path, where: str) -> np.ndarray:
    try:
        values = np.array([float(tok) for tok in text.replace(",", " ").split()], dtype=np.float64)
    except ValueError as exc:
        raise InputError(f"{path}: {where}: not a number: {one_line(exc)}") from None
    if not np.isfinite(values).all():
        raise InputError(f"{path}: {where}: non-finite number")
    return values


def _keyed_lines(text: str) -> dict[str, str]:
    """``key: values`` lines of a KITTI calibration file, as {key: values text}."""
    found = (re.match(r"\s*([A-Za-z_][\w]*)\s*:(.*)", line) for line in text.splitlines())
    return {m.group(1): m.group(2) for m in found if m}


def _homogeneous(top: np.ndarray) -> np.ndarray:
    """(K, 3, 4) -> (K, 4, 4) with last row (0, 0, 0, 1)."""
    out = np.zeros((len(top), 4, 4), dtype=np.float64)
    out[:, :3, :] = top
    out[:, 3, 3] = 1.0
    return out


def _check_poses(poses: np.ndarray, path: Path) -> np.ndarray:
    """Check a (K, 4, 4) stack of finite homogeneous transforms; returns it."""
    if poses.ndim != 3 or poses.shape[1:] != (4, 4) or len(poses) == 0:
        raise InputError(f"{path}: expected K x 4 x 4 poses, got shape {poses.shape}")
    if not np.isfinite(poses).all():
        raise InputError(f"{path}: non-finite pose")
    bottom = np.abs(poses[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max()
    if bottom > _TOLERANCE:
        raise InputError(f"{path}: a pose's last row is not 0 0 0 1")
    return poses


def _format_rows(rows: np.ndarray) -> str:
    """Rows of floats, single-space separated, shortest exact (repr) form."""
    return "".join(" ".join(repr(float(v)) for v in row) + "\n" for row in rows)
