"""Voxel centroids of a large 3D cloud in one pass over its points, read in chunks: a hash table
of voxels (open addressing, compiled by Numba) holds each voxel's running sums and count, so
memory grows with the voxels, not the points, and nothing is sorted but the voxels at the end.

Each voxel adds its points in their order, as :func:`pcmapq.core.voxels.voxel_centroids` does:
the centroids are the same bit for bit, in the same order (sorted by voxel index).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from pcmapq.core.errors import InputError

#: Bits of each axis's index in a packed key, and the offset that makes indices non-negative
#: (as :func:`pcmapq.core.voxels.voxel_keys` packs them in 3D).
BITS = 21
OFFSET = 1 << (BITS - 1)
#: Points handed to the compiled loop at once (the float64 copy of a chunk: 24 bytes each).
CHUNK = 1_000_000
#: The table grows (doubles) when this share of its slots is used.
LOAD = 0.6
EMPTY = -1
GOLDEN = np.uint64(11400714819323198485)


@numba.njit(cache=True, nogil=True)
def _slot(key: int, keys: np.ndarray, shift: np.uint64) -> int:
    """The slot holding ``key`` or the empty one where it goes (linear probing)."""
    mask = np.int64(len(keys) - 1)
    h = np.int64((np.uint64(key) * GOLDEN) >> shift) & mask
    while keys[h] != EMPTY and keys[h] != key:
        h = (h + np.int64(1)) & mask
    return h


@numba.njit(cache=True, nogil=True)
def _add(points: np.ndarray, scale: float, voxel: float, keys: np.ndarray, sums: np.ndarray,
         counts: np.ndarray, used: int, shift: np.uint64, limit: int) -> tuple[int, int]:
    """Add ``points`` (N, 3) times ``scale`` to the table until ``limit`` slots are used:
    (points added, slots used); points added is -1 - i when point i lies beyond the keys'
    range."""
    top = 1 << BITS
    for i in range(points.shape[0]):
        if used >= limit:
            return i, used
        x = points[i, 0] * scale
        y = points[i, 1] * scale
        z = points[i, 2] * scale
        ix = math.floor(x / voxel) + OFFSET
        iy = math.floor(y / voxel) + OFFSET
        iz = math.floor(z / voxel) + OFFSET
        if ix < 0 or iy < 0 or iz < 0 or ix >= top or iy >= top or iz >= top:
            return -1 - i, used
        key = (((np.int64(ix) << BITS) | np.int64(iy)) << BITS) | np.int64(iz)
        h = _slot(key, keys, shift)
        if keys[h] == EMPTY:
            keys[h] = key
            used += 1
        sums[h, 0] += x
        sums[h, 1] += y
        sums[h, 2] += z
        counts[h] += 1
    return points.shape[0], used


@numba.njit(cache=True, nogil=True)
def _moved(keys: np.ndarray, sums: np.ndarray, counts: np.ndarray, size: int,
           shift: np.uint64) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The table's voxels in a table of ``size`` slots (a power of two)."""
    new_keys = np.full(size, EMPTY, dtype=np.int64)
    new_sums = np.zeros((size, 3))
    new_counts = np.zeros(size, dtype=np.int64)
    for h in range(len(keys)):
        if keys[h] != EMPTY:
            g = _slot(keys[h], new_keys, shift)
            new_keys[g] = keys[h]
            new_sums[g] = sums[h]
            new_counts[g] = counts[h]
    return new_keys, new_sums, new_counts


def streamed_centroids(points: np.ndarray, voxel: float, scale: float = 1.0) -> np.ndarray:
    """(M, 3) float64: the centroid of ``points`` (N, 3, any float type, e.g. mapped onto a
    file) times ``scale``, metres, in each ``voxel``-metre cell, sorted by voxel index; the
    same as ``voxel_centroids(points * scale, voxel)`` bit for bit. Reads ``points`` in
    chunks of ``CHUNK`` rows. InputError when a point lies beyond +-2**20 voxels."""
    if not voxel > 0:
        raise InputError(f"voxel must be positive, got {voxel}")
    bits = 16
    keys, sums = np.full(1 << bits, EMPTY, dtype=np.int64), np.zeros((1 << bits, 3))
    counts, used = np.zeros(1 << bits, dtype=np.int64), 0
    for start in range(0, len(points), CHUNK):
        chunk = np.ascontiguousarray(points[start:start + CHUNK], dtype=np.float64)
        done = 0
        while done < len(chunk):
            added, used = _add(chunk[done:], float(scale), float(voxel), keys, sums, counts,
                               used, np.uint64(64 - bits), int(LOAD * len(keys)))
            if added < 0:
                raise InputError(f"map extends beyond +-{OFFSET * voxel:.0f} m of its origin at "
                                 f"voxel {voxel} m; use a larger voxel")
            done += added
            if done < len(chunk):
                bits += 1
                keys, sums, counts = _moved(keys, sums, counts, 1 << bits, np.uint64(64 - bits))
    held = np.flatnonzero(keys != EMPTY)
    held = held[np.argsort(keys[held], kind="stable")]
    return sums[held] / counts[held, None]
