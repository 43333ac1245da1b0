"""A map built from scans placed at their poses (a SLAM run's output), and map-metrics'
orthogonal-subset files.

Poses are 4x4 rigid transforms taking scan coordinates to the world, metres. The map is every
scan placed at its pose relative to the first: ``inv(T_0) @ T_i`` (as map-metrics'
``aggregate_map``), so it is in the first scan's frame.
"""

from __future__ import annotations

import pickle
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.lib import format as npy

from pcmapq.errors import InputError
from pcmapq.io.clouds import CLOUD_SUFFIXES, load_cloud


def place(clouds: Sequence[np.ndarray], poses: Sequence[np.ndarray]) -> np.ndarray:
    """Stack (N_i, 3) clouds, each moved by ``inv(poses[0]) @ poses[i]`` -> (sum N_i, 3) metres."""
    if len(clouds) != len(poses):
        raise ValueError(f"{len(clouds)} clouds but {len(poses)} poses")
    if not clouds:
        return np.zeros((0, 3))
    first = np.linalg.inv(np.asarray(poses[0], dtype=np.float64))
    out = []
    for cloud, pose in zip(clouds, poses, strict=True):
        t = first @ np.asarray(pose, dtype=np.float64)
        out.append(np.asarray(cloud, dtype=np.float64) @ t[:3, :3].T + t[:3, 3])
    return np.vstack(out)


def read_pose_file(path: Path) -> np.ndarray:
    """One 4x4 pose from a text file (4 rows of 4 numbers; a 3x4 top is accepted)."""
    try:
        m = np.loadtxt(path, dtype=np.float64, ndmin=2)
    except (ValueError, OSError) as exc:
        raise InputError(f"{path}: not a 4x4 pose: {exc}") from None
    if m.shape == (3, 4):
        m = np.vstack([m, [0.0, 0.0, 0.0, 1.0]])
    if m.shape != (4, 4) or not np.all(np.isfinite(m)):
        raise InputError(f"{path}: expected a 4x4 pose, got shape {m.shape}")
    return m


def read_poses(path: Path) -> list[np.ndarray]:
    """Poses from a folder of 4x4 text files (name order), a KITTI file (12 numbers a line:
    the top 3x4, row-major) or a TUM file (8 numbers a line: t x y z qx qy qz qw)."""
    path = Path(path)
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.is_file())
        if not files:
            raise InputError(f"{path}: no pose files in the folder")
        return [read_pose_file(p) for p in files]
    try:
        table = np.loadtxt(path, dtype=np.float64, ndmin=2, comments="#")
    except (ValueError, OSError) as exc:
        raise InputError(f"{path}: not a KITTI or TUM pose file: {exc}") from None
    if table.shape[1] == 12:
        tops = table.reshape(-1, 3, 4)
        bottom = np.broadcast_to([0.0, 0.0, 0.0, 1.0], (len(tops), 1, 4))
        return list(np.concatenate([tops, bottom], axis=1))
    if table.shape[1] == 8:
        return list(_tum(table[:, 1:4], table[:, 4:8]))
    raise InputError(f"{path}: expected 12 (KITTI) or 8 (TUM) numbers a line, "
                     f"got {table.shape[1]}")


def _tum(t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(N, 3) translations and (N, 4) quaternions x, y, z, w -> (N, 4, 4) poses."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    x, y, z, w = q.T
    out = np.zeros((len(q), 4, 4))
    out[:, 0] = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                          t[:, 0]], axis=1)
    out[:, 1] = np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                          t[:, 1]], axis=1)
    out[:, 2] = np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y),
                          t[:, 2]], axis=1)
    out[:, 3, 3] = 1.0
    return out


def scan_files(folder: Path) -> list[Path]:
    """The point-cloud files of a folder, in name order."""
    files = sorted(p for p in Path(folder).iterdir() if p.suffix.lower() in CLOUD_SUFFIXES)
    if not files:
        raise InputError(f"{folder}: no scans ({', '.join(CLOUD_SUFFIXES)}) in the folder")
    return files


def load_posed_map(scans: Path, poses: Path) -> np.ndarray:
    """The map (N, 3 metres, first scan's frame) of the scans in folder ``scans`` placed at the
    poses of ``poses`` (see :func:`read_poses`); one pose per scan, in name order."""
    files = scan_files(scans)
    transforms = read_poses(poses)
    if len(transforms) != len(files):
        raise InputError(f"{poses}: {len(transforms)} poses for {len(files)} scans in {scans}")
    return place([load_cloud(f).points for f in files], transforms)


class _ArraysOnly(pickle.Unpickler):
    """Unpickles NumPy arrays and nothing else (an object .npy is a pickle: never run code)."""

    ALLOWED = {("numpy.core.multiarray", "_reconstruct"),
               ("numpy._core.multiarray", "_reconstruct"), ("numpy", "ndarray"), ("numpy", "dtype")}

    def find_class(self, module: str, name: str) -> type:
        if (module, name) not in self.ALLOWED:
            raise pickle.UnpicklingError(f"{module}.{name} is not a NumPy array part")
        return super().find_class(module, name)


def read_orthogonal_subset(path: Path) -> list[np.ndarray]:
    """map-metrics' orthogonal subset: a .npy holding an object array of (K_i, 3) arrays, one
    per plane (read without running any pickled code), or a .npz of (K_i, 3) arrays."""
    path = Path(path)
    try:
        if path.suffix.lower() == ".npz":
            with np.load(path, allow_pickle=False) as z:
                planes = [z[k] for k in z.files]
        else:
            planes = _object_npy(path)
    except (ValueError, OSError, EOFError, pickle.UnpicklingError) as exc:
        raise InputError(f"{path}: not an orthogonal subset: {exc}") from None
    out = [np.asarray(p, dtype=np.float64) for p in planes]
    if not out or any(p.ndim != 2 or p.shape[1] != 3 for p in out):
        raise InputError(f"{path}: expected one or more (K, 3) arrays of points")
    return out


def _object_npy(path: Path) -> list[np.ndarray]:
    with path.open("rb") as f:
        version = npy.read_magic(f)
        read = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
        shape, _, dtype = read(f, max_header_size=10_000)
        if not dtype.hasobject:  # one (K, 3) plane or a stack (P, K, 3) of them
            array = np.load(path, allow_pickle=False)
            return [array] if len(shape) == 2 else list(array)
        return list(_ArraysOnly(f).load())


def place_subset(planes: Sequence[np.ndarray], pose: np.ndarray,
                 first_pose: np.ndarray) -> list[np.ndarray]:
    """An orthogonal subset saved in the frame of the scan at ``pose``, moved into the map's
    frame (the first scan's, pose ``first_pose``), as map-metrics' ``read_orthogonal_subset``."""
    t = np.linalg.inv(np.asarray(first_pose, dtype=np.float64)) @ np.asarray(pose, np.float64)
    return [np.asarray(p, dtype=np.float64) @ t[:3, :3].T + t[:3, 3] for p in planes]
