"""Each point's normal and surface variation from the covariance of its neighbours: the least
eigenvector and the least eigenvalue over their sum (0 on a plane, 1/3 where points scatter
alike in every direction). Metres, in the points' frame.

The least eigenpair of each 3 x 3 covariance is found in closed form, in a compiled loop over
the points: the eigenvalue by the trigonometric solution of the characteristic cubic, polished
by two Newton steps; its eigenvector as the largest cross product of two rows of the
covariance less that eigenvalue. Where the two least eigenvalues are within SEPARATION of the
largest (a line's or a blob's neighbourhood, whose least eigenvector is barely defined) or all
three are equal, LAPACK's ``eigh`` gives both, as it does the others' to about 1e-14 (a tenth of
the time of LAPACK for every point).
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["normals_and_variation"]

#: Two least eigenvalues closer than this share of the largest: LAPACK's eigenpair instead.
SEPARATION = 1e-2
#: Newton steps that polish the trigonometric least eigenvalue.
NEWTON = 2


def normals_and_variation(points: np.ndarray, near: np.ndarray
                          ) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (K, 3) (either sign) and surface variations (K,) of the neighbourhoods
    ``near`` (K, k) indices into ``points`` (N, 3), each about its mean."""
    normal, variation = np.empty((len(near), 3)), np.empty(len(near))
    odd = np.empty(len(near), np.int64)
    count = _least(points, near, normal, variation, odd)
    if count:
        rows = odd[:count]
        values, vectors = np.linalg.eigh(_covariances(points, near[rows]))
        variation[rows] = values[:, 0] / np.maximum(values.sum(axis=1), 1e-18)
        normal[rows] = vectors[:, :, 0]
    return normal, variation


@numba.njit(cache=True, nogil=True, inline="always")
def _moments(points: np.ndarray, row: np.ndarray) -> tuple:
    """The covariance's six entries (xx, xy, xz, yy, yz, zz) of the points ``row`` (k,)."""
    k = len(row)
    mx = my = mz = 0.0
    for a in range(k):
        j = row[a]
        mx += points[j, 0]
        my += points[j, 1]
        mz += points[j, 2]
    mx, my, mz = mx / k, my / k, mz / k
    xx = xy = xz = yy = yz = zz = 0.0
    for a in range(k):
        j = row[a]
        dx, dy, dz = points[j, 0] - mx, points[j, 1] - my, points[j, 2] - mz
        xx += dx * dx
        xy += dx * dy
        xz += dx * dz
        yy += dy * dy
        yz += dy * dz
        zz += dz * dz
    return xx / k, xy / k, xz / k, yy / k, yz / k, zz / k


@numba.njit(cache=True, nogil=True)
def _covariances(points: np.ndarray, near: np.ndarray) -> np.ndarray:
    """(K, 3, 3) the covariance of each row of ``near``'s (K, k) points, about their mean."""
    out = np.empty((near.shape[0], 3, 3))
    for i in range(near.shape[0]):
        xx, xy, xz, yy, yz, zz = _moments(points, near[i])
        out[i, 0, 0], out[i, 1, 1], out[i, 2, 2] = xx, yy, zz
        out[i, 0, 1] = out[i, 1, 0] = xy
        out[i, 0, 2] = out[i, 2, 0] = xz
        out[i, 1, 2] = out[i, 2, 1] = yz
    return out


@numba.njit(cache=True, nogil=True)
def _least(points: np.ndarray, near: np.ndarray, normal: np.ndarray, variation: np.ndarray,
           odd: np.ndarray) -> int:
    """Each row's normal and variation in closed form (module docstring) into ``normal`` and
    ``variation``; the rows left to LAPACK into ``odd``; returns how many."""
    count = 0
    for i in range(near.shape[0]):
        xx, xy, xz, yy, yz, zz = _moments(points, near[i])
        q = (xx + yy + zz) / 3.0
        p = np.sqrt(((xx - q) ** 2 + (yy - q) ** 2 + (zz - q) ** 2
                     + 2.0 * (xy * xy + xz * xz + yz * yz)) / 6.0)
        if p <= 0.0:
            odd[count] = i
            count += 1
            continue
        b00, b11, b22, b01, b02, b12 = (xx - q) / p, (yy - q) / p, (zz - q) / p, xy / p, \
            xz / p, yz / p
        half_det = 0.5 * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02)
                          + b02 * (b01 * b12 - b11 * b02))
        phi = np.arccos(min(max(half_det, -1.0), 1.0)) / 3.0
        most = q + 2.0 * p * np.cos(phi)
        least = q + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)
        for _ in range(NEWTON):  # det(A - l I) and its derivative in l
            a00, a11, a22 = xx - least, yy - least, zz - least
            m0, m1, m2 = a11 * a22 - yz * yz, a00 * a22 - xz * xz, a00 * a11 - xy * xy
            slope = -(m0 + m1 + m2)
            if slope != 0.0:
                least -= (a00 * m0 - xy * (xy * a22 - yz * xz) + xz * (xy * yz - a11 * xz)) \
                    / slope
        if (3.0 * q - most - least) - least <= SEPARATION * most:
            odd[count] = i
            count += 1
            continue
        a00, a11, a22 = xx - least, yy - least, zz - least
        # the cross products of the rows (a00, xy, xz), (xy, a11, yz), (xz, yz, a22)
        c0 = (xy * yz - xz * a11, xz * xy - a00 * yz, a00 * a11 - xy * xy)
        c1 = (xy * a22 - xz * yz, xz * xz - a00 * a22, a00 * yz - xy * xz)
        c2 = (a11 * a22 - yz * yz, yz * xz - xy * a22, xy * yz - a11 * xz)
        s0 = c0[0] ** 2 + c0[1] ** 2 + c0[2] ** 2
        s1 = c1[0] ** 2 + c1[1] ** 2 + c1[2] ** 2
        s2 = c2[0] ** 2 + c2[1] ** 2 + c2[2] ** 2
        if s0 >= s1 and s0 >= s2:
            best, size = c0, s0
        elif s1 >= s2:
            best, size = c1, s1
        else:
            best, size = c2, s2
        scale = 1.0 / np.sqrt(size)
        normal[i, 0], normal[i, 1], normal[i, 2] = best[0] * scale, best[1] * scale, \
            best[2] * scale
        variation[i] = least / max(3.0 * q, 1e-18)
    return count
