"""Scans placed at their poses as map-metrics places them, and its orthogonal-subset files.

Poses are 4x4 rigid transforms taking scan coordinates to the world, metres. The map is every
scan placed at its pose relative to the first: ``inv(T_0) @ T_i`` (as map-metrics'
``aggregate_map``), so it is in the first scan's frame. Pose files and scan folders are read by
:mod:`pcmapq.mapping` (:func:`pcmapq.mapping.reference.posed_map`).
"""

from __future__ import annotations

import pickle
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.lib import format as npy

from pcmapq.core.errors import InputError
from pcmapq.core.transform import affine
from pcmapq.core.words import count


def place(clouds: Sequence[np.ndarray], poses: Sequence[np.ndarray]) -> np.ndarray:
    """Stack (N_i, 3) clouds, each moved by ``inv(poses[0]) @ poses[i]`` -> (sum N_i, 3) metres."""
    if len(clouds) != len(poses):
        raise ValueError(f"{count(len(clouds), 'cloud')} but {count(len(poses), 'pose')}")
    if not clouds:
        return np.zeros((0, 3))
    first = np.linalg.inv(np.asarray(poses[0], dtype=np.float64))
    out = []
    for cloud, pose in zip(clouds, poses, strict=True):
        t = first @ np.asarray(pose, dtype=np.float64)
        out.append(affine(np.asarray(cloud, dtype=np.float64), t))
    return np.vstack(out)


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
    return [affine(np.asarray(p, dtype=np.float64), t) for p in planes]
