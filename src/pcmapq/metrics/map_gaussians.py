"""MapEval's map figures between two 3D clouds in one frame (Hu et al., RA-L 2025; definitions
and where they differ from MapEval's code in docs/metrics.md): each cloud cut into cubic
voxels, the points of a voxel summed up as a Gaussian (mean, sample covariance); AWD, the mean
2-Wasserstein distance between the two clouds' Gaussians of the voxels both fill, metres; SCS,
how much those distances vary among neighbouring voxels (a coefficient of variation, no unit).

Vectorised and streamed by voxel: the clouds are read CHUNK points at a time (a file mapped into
memory is never converted whole) and each voxel's count, sums and sums of products are
accumulated by ``np.add.at`` on packed voxel keys, in the points' order (the same sums, bit for
bit, as one ``np.bincount`` over all of them); the distances by batched eigendecompositions of
3 x 3 matrices; the neighbourhoods by sorted keys (one pass per column of neighbours, never per
voxel)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pcmapq.core.bounds import bounds
from pcmapq.core.covariance import PAIRS, symmetric
from pcmapq.core.errors import InputError
from pcmapq.core.voxels import index_keys, voxel_index, voxel_keys
from pcmapq.metrics.defaults import AWD_MIN_POINTS, AWD_VOXEL, SCS_RADIUS

#: Eigenvalues of a voxel's covariance are raised to at least this, m^2 (MapEval's floor): a
#: flat voxel (a wall) keeps a finite thickness.
COVARIANCE_FLOOR = 1e-6
#: A squared distance within this share of the two covariances' traces is rounding, and 0
#: (identical Gaussians computed in two orders): below a micrometre for metre-sized voxels.
ROUNDING = 1e-12
#: Bits of an axis in a packed voxel key (:func:`pcmapq.core.voxels.voxel_keys`, 3D).
_BITS = 21
#: Points read at a time (their float64 copy, voxel indices and keys: about 40 MB).
CHUNK = 1 << 19
#: A cloud's voxels are every voxel of its box when the box holds at most this many (and at
#: most DENSE_PER_POINT a point): their sums are then found without a pass to list them.
DENSE_CELLS, DENSE_PER_POINT = 1 << 20, 4


@dataclass(frozen=True)
class MapGaussians:
    """AWD (metres) and SCS (no unit) of two clouds, each None when nothing was compared.

    voxels: the voxels both clouds hold at least ``min_points`` points in (AWD's mean is
    over them); basis: what the figures are computed on, in words."""

    awd_m: float | None
    scs: float | None
    voxels: int
    basis: str = ""


def map_gaussians(map_xyz: np.ndarray, truth_xyz: np.ndarray, voxel: float = AWD_VOXEL,
                  min_points: int = AWD_MIN_POINTS, radius: int = SCS_RADIUS) -> MapGaussians:
    """AWD and SCS of a map cloud (N, 3) against a truth cloud (M, 3), metres, both in the
    truth's frame, on ``voxel``-metre cubes (floor of each coordinate over the voxel, as
    MapEval). A voxel counts when each cloud holds at least ``min_points`` points in it; SCS
    looks at the counted voxels within ``radius`` voxels along every axis (a cube of side
    ``2 * radius + 1``, the voxel itself left out). InputError for clouds spanning more than
    about a million voxels."""
    basis = (f"in 3D: {voxel:g} m voxels holding at least {min_points} points of each cloud, "
             f"one Gaussian per voxel and cloud; SCS over neighbours within {radius} voxels")
    map_xyz, truth_xyz = (np.asarray(c).reshape(-1, 3) for c in (map_xyz, truth_xyz))
    # keyed from a corner of whole voxels below both clouds: the same voxels, and keys that
    # fit however far from the origin the clouds lie (UTM coordinates)
    both = [bounds(c)[0].astype(np.float64) for c in (map_xyz, truth_xyz) if len(c)]
    corner = np.floor(np.min(both, axis=0) / voxel) * voxel if both else np.zeros(3)
    keys_m, mean_m, cov_m = voxel_gaussians(map_xyz, voxel, min_points, corner)
    keys_t, mean_t, cov_t = voxel_gaussians(truth_xyz, voxel, min_points, corner)
    common, in_m, in_t = np.intersect1d(keys_m, keys_t, assume_unique=True,
                                        return_indices=True)
    if len(common) == 0:
        return MapGaussians(None, None, 0, basis)
    w = gaussian_w2(mean_t[in_t], cov_t[in_t], mean_m[in_m], cov_m[in_m])
    return MapGaussians(float(w.mean()), spatial_consistency(common, w, radius),
                        int(len(common)), basis)


def voxel_gaussians(points: np.ndarray, voxel: float, min_points: int = 2,
                    origin: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The voxels of ``points`` (N, 3, metres, any float type) minus ``origin`` (3,) metres
    (default 0) holding at least ``min_points`` (>= 2) of them: their packed keys (V,) int64
    sorted (:func:`~pcmapq.core.voxels.voxel_keys`), the mean (V, 3) of their points, metres,
    and its sample covariance (V, 3, 3, divided by n - 1), square metres, all in the frame of
    ``origin``. Three passes over the points, CHUNK at a time, none held whole: the voxels,
    their counts and sums (the means), then the products about the means: exact far from the
    origin."""
    points = np.asarray(points).reshape(-1, 3)
    origin = np.zeros(3) if origin is None else np.asarray(origin, dtype=np.float64)
    keys, rows = _cells(points, origin, voxel)
    n, sums = np.zeros(len(keys)), np.zeros((3, len(keys)))
    for chunk in _chunks(points, origin):
        at = rows(chunk)
        np.add.at(n, at, 1.0)
        for a in range(3):
            np.add.at(sums[a], at, chunk[:, a])
    means = sums / np.maximum(n, 1.0)
    products = np.zeros((len(PAIRS), len(keys)))
    for chunk in _chunks(points, origin):
        at = rows(chunk)
        centred = [chunk[:, a] - np.take(means[a], at) for a in range(3)]
        for k, (a, b) in enumerate(PAIRS):
            np.add.at(products[k], at, centred[a] * centred[b])
    kept = n >= max(min_points, 2)
    return keys[kept], means.T[kept], symmetric(products[:, kept] / (n[kept] - 1))


def _cells(points: np.ndarray, origin: np.ndarray, voxel: float
           ) -> tuple[np.ndarray, Callable[[np.ndarray], np.ndarray]]:
    """The voxels the points (N, 3) minus ``origin`` may fill, as packed keys (sorted), and a
    function giving the rows among them of a chunk of those points: every voxel of the
    points' box when it holds at most DENSE_CELLS (no pass over the points to find them; the
    empty ones count no point), else the voxels found in a pass. InputError for points beyond
    the keys' range."""
    if len(points):
        lo, hi = (b.astype(np.float64) - origin for b in bounds(points))
        first, last = voxel_index(np.array([lo, hi]), voxel)
        span = last - first + 1
        cells = int(np.prod(span.astype(object)))
        if cells <= min(DENSE_CELLS, DENSE_PER_POINT * len(points) + 4096):
            keys = index_keys(np.column_stack(np.unravel_index(np.arange(cells), tuple(span)))
                              + first)

            def rows(chunk: np.ndarray) -> np.ndarray:  # row-major in the box: as the keys
                index = voxel_index(chunk, voxel) - first
                return (index[:, 0] * span[1] + index[:, 1]) * span[2] + index[:, 2]

            return keys, rows
    keys = np.empty(0, dtype=np.int64)
    for chunk in _chunks(points, origin):
        keys = np.union1d(keys, voxel_keys(chunk, voxel))
    return keys, lambda chunk: np.searchsorted(keys, voxel_keys(chunk, voxel))


def _chunks(points: np.ndarray, origin: np.ndarray):
    """The points (N, 3) CHUNK rows at a time, minus ``origin``, as contiguous float64."""
    for start in range(0, len(points), CHUNK):
        yield np.ascontiguousarray(points[start:start + CHUNK] - origin, dtype=np.float64)


def gaussian_w2(mean_a: np.ndarray, cov_a: np.ndarray, mean_b: np.ndarray,
                cov_b: np.ndarray) -> np.ndarray:
    """The 2-Wasserstein distance (V,), metres, between Gaussians paired by row: means (V, 3)
    metres, covariances (V, 3, 3) square metres, each covariance's eigenvalues first raised to
    :data:`COVARIANCE_FLOOR`. ``W^2 = |ma - mb|^2 + tr(A + B - 2 (A^1/2 B A^1/2)^1/2)`` with
    symmetric square roots (eigendecompositions)."""
    a, b = _floored(cov_a), _floored(cov_b)
    value, vector = np.linalg.eigh(a)
    root = (vector * np.sqrt(value)[:, None, :]) @ vector.transpose(0, 2, 1)
    middle = root @ b @ root
    middle = 0.5 * (middle + middle.transpose(0, 2, 1))
    cross = np.sqrt(np.clip(np.linalg.eigvalsh(middle), 0.0, None)).sum(axis=1)
    spread = np.trace(a, axis1=1, axis2=2) + np.trace(b, axis1=1, axis2=2)
    squared = np.sum((mean_a - mean_b) ** 2, axis=1) + spread - 2.0 * cross
    squared[squared <= ROUNDING * spread] = 0.0
    return np.sqrt(squared)


def spatial_consistency(keys: np.ndarray, w: np.ndarray, radius: int) -> float | None:
    """SCS: over the voxels (packed keys (V,) sorted, their distances ``w`` (V,), metres) that
    have any other voxel within ``radius`` voxels along every axis, the mean of those
    neighbours' coefficient of variation (population standard deviation over mean; 0 where
    their mean is 0). None when no voxel has a neighbour.

    One pass per (dx, dy) column of the neighbourhood: the keys of a column's voxels z - radius
    to z + radius are one range of the sorted keys (z is a key's lowest bits), so prefix sums
    over it give each voxel's count, sum and sum of squares."""
    index = (keys[:, None] >> np.array([2 * _BITS, _BITS, 0])) & ((1 << _BITS) - 1)
    if len(keys) and (index.min() < radius or index.max() >= (1 << _BITS) - radius):
        raise InputError("a cloud reaches the edge of the voxel index; use a larger voxel")
    centre = float(w.mean()) if len(w) else 0.0  # sums about it: no cancellation
    shifted = w - centre
    sums = np.concatenate([[0.0], np.cumsum(shifted)])
    squares = np.concatenate([[0.0], np.cumsum(shifted**2)])
    nonzero = np.concatenate([[0], np.cumsum(w > 0)])
    count, moving = np.zeros(len(keys), dtype=np.int64), np.zeros(len(keys), dtype=np.int64)
    total, total_sq = np.zeros(len(keys)), np.zeros(len(keys))
    for dx in range(-radius, radius + 1):
        for dy in range(-radius, radius + 1):
            column = keys + (dx << 2 * _BITS) + (dy << _BITS)
            lo = np.searchsorted(keys, column - radius, side="left")
            hi = np.searchsorted(keys, column + radius, side="right")
            count += hi - lo
            moving += nonzero[hi] - nonzero[lo]
            total += sums[hi] - sums[lo]
            total_sq += squares[hi] - squares[lo]
    count -= 1  # the voxel itself is not its own neighbour
    total, total_sq = total - shifted, total_sq - shifted**2
    moving -= w > 0
    has = count > 0
    if not has.any():
        return None
    n = count[has]
    mean = total[has] / n + centre
    variance = np.clip(total_sq[has] / n - (total[has] / n) ** 2, 0.0, None)
    ratio = np.divide(np.sqrt(variance), mean, out=np.zeros_like(mean),
                      where=moving[has] > 0)  # all neighbours at 0: perfectly consistent
    return float(ratio.mean())


def _floored(cov: np.ndarray) -> np.ndarray:
    """Covariances (V, 3, 3) symmetrised, their eigenvalues raised to COVARIANCE_FLOOR."""
    value, vector = np.linalg.eigh(0.5 * (cov + cov.transpose(0, 2, 1)))
    return (vector * np.maximum(value, COVARIANCE_FLOOR)[:, None, :]) @ \
        vector.transpose(0, 2, 1)
