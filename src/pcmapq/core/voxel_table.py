"""Voxel centroids of a large 2D or 3D cloud in one pass over its points, read in chunks: a hash
table of voxels (open addressing, compiled by Numba) holds each voxel's running sums and count,
so memory grows with the voxels, not the points, and nothing is sorted but the voxels at the end.

Each voxel adds its points in their order, as :func:`pcmapq.core.voxels.voxel_centroids` does:
the centroids are the same bit for bit, in the same order (sorted by voxel index).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np

from pcmapq.core.errors import InputError

#: Points handed to the compiled loop at once (the float64 copy of a chunk: 8 bytes a
#: coordinate, 6 MB in 3D): small beside the table, and large enough that the calls into the
#: loop cost nothing beside its work.
CHUNK = 1 << 18
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
def _add(points: np.ndarray, scale: float, voxel: float, origin: np.ndarray, keys: np.ndarray,
         sums: np.ndarray, counts: np.ndarray, used: int, shift: np.uint64, limit: int, lo: int,
         hi: int) -> tuple[int, int]:
    """Add the ``points`` (N, d) times ``scale`` whose x index (offset as in the keys) lies in
    [lo, hi) to the table until ``limit`` slots are used: (points gone through, slots used);
    -1 - i when point i lies beyond the keys' range. A point's voxel counts from ``origin``
    (d,) metres: ``floor((p * scale - origin) / voxel)``. Keys pack each axis's index in
    63 // d bits, as :func:`pcmapq.core.voxels.voxel_keys` does."""
    dims = points.shape[1]
    bits = 63 // dims
    offset = 1 << (bits - 1)
    top = 1 << bits
    for i in range(points.shape[0]):
        if used >= limit:
            return i, used
        key, inside = np.int64(0), True
        for axis in range(dims):
            index = math.floor((points[i, axis] * scale - origin[axis]) / voxel) + offset
            if index < 0 or index >= top:
                return -1 - i, used
            if axis == 0 and (index < lo or index >= hi):
                inside = False
            key = (key << bits) | np.int64(index)
        if not inside:
            continue
        h = _slot(key, keys, shift)
        if keys[h] == EMPTY:
            keys[h] = key
            used += 1
        for axis in range(dims):
            sums[h, axis] += points[i, axis] * scale
        counts[h] += 1
    return points.shape[0], used


@numba.njit(cache=True, nogil=True)
def _moved(keys: np.ndarray, sums: np.ndarray, counts: np.ndarray, size: int,
           shift: np.uint64) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The table's voxels in a table of ``size`` slots (a power of two)."""
    new_keys = np.full(size, EMPTY, dtype=np.int64)
    new_sums = np.zeros((size, sums.shape[1]))
    new_counts = np.zeros(size, dtype=np.int64)
    for h in range(len(keys)):
        if keys[h] != EMPTY:
            g = _slot(keys[h], new_keys, shift)
            new_keys[g] = keys[h]
            new_sums[g] = sums[h]
            new_counts[g] = counts[h]
    return new_keys, new_sums, new_counts


def streamed_centroids(points: np.ndarray, voxel: float, scale: float = 1.0,
                       move: Callable[[np.ndarray], np.ndarray] | None = None,
                       stripe_points: int | None = None,
                       origin: np.ndarray | None = None) -> np.ndarray:
    """(M, d) float64: the centroid of ``points`` (N, d, d = 2 or 3, any float type, e.g.
    mapped onto a file) times ``scale``, metres, in each ``voxel``-metre cell, sorted by voxel
    index; the same as ``voxel_centroids(points * scale, voxel)`` bit for bit. Reads ``points``
    in chunks of ``CHUNK`` rows, each passed through ``move`` first when given (a transform of
    rows, such as into another frame: the centroids of the moved points, none of them held
    whole). ``stripe_points``: with more points than this, the voxels are found in one stripe
    of x after another, a pass over the points each (N / stripe_points stripes of equal
    width), so that the table holds one stripe's voxels at a time; the keys sort by x first,
    so the stripes' centroids follow one another in order. ``origin`` (d,) metres: the voxels
    are the cubes ``origin + voxel * (i, j, k)`` (default: from 0). InputError when a point
    lies beyond the keys' range (+-2**20 voxels from ``origin`` in 3D)."""
    if not voxel > 0:
        raise InputError(f"voxel must be positive, got {voxel}")
    origin = np.zeros(points.shape[1]) if origin is None else \
        np.asarray(origin, dtype=np.float64).reshape(points.shape[1])
    stripes = 1 if stripe_points is None else max(1, -(-len(points) // stripe_points))
    if stripes == 1:
        return _stripe(points, voxel, scale, move, origin, 0, 1 << (63 // points.shape[1]))
    first, last = _x_indices(points, voxel, scale, move, origin)
    edges = first + (last + 1 - first) * np.arange(stripes + 1) // stripes
    return np.concatenate([_stripe(points, voxel, scale, move, origin, int(edges[k]),
                                   int(edges[k + 1])) for k in range(stripes)])


def _chunks(points: np.ndarray, move: Callable[[np.ndarray], np.ndarray] | None):
    """The points CHUNK rows at a time, moved, as contiguous float64."""
    for start in range(0, len(points), CHUNK):
        chunk = points[start:start + CHUNK]
        yield np.ascontiguousarray(chunk if move is None else move(chunk), dtype=np.float64)


def _x_indices(points: np.ndarray, voxel: float, scale: float,
               move: Callable[[np.ndarray], np.ndarray] | None,
               origin: np.ndarray) -> tuple[int, int]:
    """The least and greatest x index of the points' voxels, offset as in the keys (clipped to
    the keys' range: a point beyond it is refused by the pass that meets it)."""
    bits = 63 // points.shape[1]
    lowest, highest = np.inf, -np.inf
    for chunk in _chunks(points, move):
        if len(chunk):
            index = np.floor((chunk[:, 0] * scale - origin[0]) / voxel)
            lowest, highest = min(lowest, index.min()), max(highest, index.max())
    offset, top = 1 << (bits - 1), 1 << bits
    if lowest > highest:
        return 0, 0
    return (int(np.clip(lowest + offset, 0, top - 1)), int(np.clip(highest + offset, 0, top - 1)))


def _stripe(points: np.ndarray, voxel: float, scale: float,
            move: Callable[[np.ndarray], np.ndarray] | None, origin: np.ndarray, lo: int,
            hi: int) -> np.ndarray:
    """The centroids of the voxels whose x index (offset as in the keys) lies in [lo, hi), in
    one pass over the points."""
    dims, bits = points.shape[1], 16
    keys, sums = np.full(1 << bits, EMPTY, dtype=np.int64), np.zeros((1 << bits, dims))
    counts, used = np.zeros(1 << bits, dtype=np.int64), 0
    for chunk in _chunks(points, move):
        done = 0
        while done < len(chunk):
            added, used = _add(chunk[done:], float(scale), float(voxel), origin, keys, sums,
                               counts, used, np.uint64(64 - bits), int(LOAD * len(keys)), lo,
                               hi)
            if added < 0:
                reach = (1 << (63 // dims - 1)) * voxel
                raise InputError(f"map extends beyond +-{reach:.0f} m of its origin at "
                                 f"voxel {voxel} m; use a larger voxel")
            done += added
            if done < len(chunk):
                bits += 1
                keys, sums, counts = _moved(keys, sums, counts, 1 << bits, np.uint64(64 - bits))
    held = np.flatnonzero(keys != EMPTY)
    return _centroids(sums, counts, held[np.argsort(keys[held], kind="stable")])


@numba.njit(cache=True, nogil=True)
def _centroids(sums: np.ndarray, counts: np.ndarray, slots: np.ndarray) -> np.ndarray:
    """(len(slots), d): each slot's sums over its count, in the order of ``slots``, written
    straight into the result (no gathered copy of the sums beside the table)."""
    out = np.empty((len(slots), sums.shape[1]))
    for i in range(len(slots)):
        for axis in range(sums.shape[1]):
            out[i, axis] = sums[slots[i], axis] / counts[slots[i]]
    return out
