"""A raster resampled to another cell size over the same area (same origin and yaw) by exact
area averaging: the first and last steps of the wall image (:mod:`pcmapq.features.walls`)."""

from __future__ import annotations

import cv2
import numpy as np
from scipy import sparse

from pcmapq.core.grid import MetricGrid


def _overlap_matrix(n_out: int, out_size: float, n_in: int, in_size: float) -> sparse.csr_array:
    """(n_out, n_in) weights of 1D area averaging: the fraction of output cell ``i`` (length
    ``out_size``) covered by input cell ``j`` (length ``in_size``); both start at 0."""
    edges = np.union1d(np.arange(n_out + 1) * out_size, np.arange(n_in + 1) * in_size)
    edges = edges[edges <= min(n_out * out_size, n_in * in_size) + 1e-12]
    mid = 0.5 * (edges[1:] + edges[:-1])
    length = np.diff(edges)
    i = np.minimum((mid / out_size).astype(np.int64), n_out - 1)
    j = np.minimum((mid / in_size).astype(np.int64), n_in - 1)
    return sparse.csr_array((length / out_size, (i, j)), shape=(n_out, n_in))


def _whole(ratio: float) -> int:
    """``ratio`` as a whole number of at least 2, or 0 when it is not one."""
    k = int(round(ratio))
    return k if k >= 2 and abs(ratio - k) < 1e-9 * ratio else 0


def covered(mask: np.ndarray, grid: MetricGrid,
            resolution: float) -> tuple[np.ndarray, MetricGrid]:
    """The cells of a grid of ``resolution`` metres (same origin and yaw as ``grid``) that any
    part of a set cell of ``mask`` (rows, cols, bool, on ``grid``) covers: uint8 0 or 1, and the
    grid. Where each new cell lies in one old cell, it is that cell's value, found in bytes
    (no area fractions); otherwise from :func:`resample`'s fractions."""
    if _whole(grid.resolution / resolution):
        work = grid.resampled(resolution)
        return _finer(np.ascontiguousarray(mask, dtype=bool).view(np.uint8), work), work
    frac, work = resample(mask, grid, resolution)
    return (frac > 1e-6).astype(np.uint8), work


def _finer(image: np.ndarray, work: MetricGrid) -> np.ndarray:
    """``image`` on the finer grid ``work``, each of whose cells lies in one of its cells (a
    whole factor finer): that cell's value."""
    return cv2.resize(image, (work.shape[1], work.shape[0]),
                      interpolation=cv2.INTER_NEAREST_EXACT)


def resample(image: np.ndarray, grid: MetricGrid,
             resolution: float) -> tuple[np.ndarray, MetricGrid]:
    """Resample ``image`` (rows, cols, on ``grid``) to cells of ``resolution`` metres by exact
    area averaging over a grid with the same origin and yaw.

    Returns the float32 image and its grid; the area beyond the input's extent reads 0.
    """
    image = np.asarray(image, dtype=np.float32)
    if abs(grid.resolution - resolution) < 1e-9 * resolution:
        return image, grid
    work = grid.resampled(resolution)
    up, down = _whole(grid.resolution / resolution), _whole(resolution / grid.resolution)
    if up:
        return _finer(image, work), work
    if down:  # each new cell is a block of old cells; blocks start at the lower-left corner
        rows, cols = work.shape[0] * down, work.shape[1] * down
        padded = image if (rows, cols) == image.shape else \
            np.pad(image, ((rows - image.shape[0], 0), (0, cols - image.shape[1])))
        return cv2.resize(padded, work.shape[::-1], interpolation=cv2.INTER_AREA), work
    ax = _overlap_matrix(work.shape[1], resolution, grid.shape[1], grid.resolution)
    # rows count from the top, the origin is at the bottom: average the flipped rows
    ay = _overlap_matrix(work.shape[0], resolution, grid.shape[0], grid.resolution)
    out = ay @ image[::-1]
    out = (ax @ out.T).T[::-1]
    return np.ascontiguousarray(out, dtype=np.float32), work
