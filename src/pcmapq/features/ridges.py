"""Wall centre lines of an image and their straight pieces (for the Hough detector).

A pixel is on a ridge when the maximum of the smoothed image across the ridge (given by the
Hessian, Steger's detector) lies inside it; ridge pixels are split by their local direction
into 30 degree bins and every connected run of one bin is a straight piece, fitted by its
principal axis. Lengths are in pixels here; :mod:`pcmapq.features.hough` converts.
"""

from __future__ import annotations

import cv2
import numpy as np

from pcmapq.features.base import gaussian
from pcmapq.features.pixels import flat_index, neighbour_pairs
from pcmapq.features.pixels import pieces as connected


def ridges(image: np.ndarray, sigma_px: float,
           floor: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One-pixel centre lines of the bright ridges of ``image`` (Steger's detector), and their
    local direction.

    A pixel is on a ridge when the maximum of the smoothed image across the ridge (along the
    Hessian's most negative eigenvector, to second order) lies inside the pixel: the line is
    one pixel wide wherever the wall's centre falls between pixels. Blob-like points (curved as
    much along as across, i.e. wall ends) are left out, so the lines stop short of wall ends
    and T junctions instead of fanning out.

    Parameters
    ----------
    image : (rows, cols) float32 in [0, 1].
    sigma_px : smoothing scale, pixels.
    floor : least ridge strength ``-sigma^2 * lambda`` (scale-normalised second derivative
        across the ridge), dimensionless.

    Returns
    -------
    mask : (rows, cols) bool mask of ridge pixels.
    direction : (rows, cols) float32 direction along the ridge, radians in [0, pi) measured
        from the pixel u axis towards v (on strong line-like pixels, 0 elsewhere).
    smooth : (rows, cols) float32, the image smoothed with ``sigma_px``.
    """
    s = gaussian(image, sigma_px)

    def diff(du: int, dv: int, scale: float) -> np.ndarray:
        return cv2.Sobel(s, cv2.CV_32F, du, dv, ksize=3, borderType=cv2.BORDER_REFLECT) / scale

    a, c, b = diff(2, 0, 4.0), diff(0, 2, 4.0), diff(1, 1, 4.0)
    root = np.sqrt(0.25 * (a - c) ** 2 + b * b)
    lam, along = 0.5 * (a + c) - root, 0.5 * (a + c) + root  # across and along the ridge
    line_like = np.abs(along) <= 0.5 * np.abs(lam)  # not a blob (a wall end)
    # the rest only where the ridge is strong and line-like (a few percent of the pixels)
    at = np.flatnonzero(line_like & (-lam * sigma_px**2 >= floor))
    a, c, b, lam = a.ravel()[at], c.ravel()[at], b.ravel()[at], lam.ravel()[at]
    gu, gv = diff(1, 0, 8.0).ravel()[at], diff(0, 1, 8.0).ravel()[at]
    theta = 0.5 * np.arctan2(2 * b, a - c) + 0.5 * np.pi  # eigenvector of lam: across
    nu, nv = np.cos(theta), np.sin(theta)
    t = -(gu * nu + gv * nv) / np.minimum(lam, -1e-12)  # distance to the maximum, pixels
    inside = (np.abs(t * nu) <= 0.5) & (np.abs(t * nv) <= 0.5)
    mask = np.zeros(s.shape, dtype=bool)
    mask.ravel()[at[inside]] = True
    direction = np.zeros(s.shape, dtype=np.float32)
    direction.ravel()[at] = np.mod(theta + 0.5 * np.pi, np.pi)
    return mask, direction, s


#: Direction bins of one partition of the ridge pixels (30 degrees each).
_BINS = 6


def _label(bins: np.ndarray, pairs: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, int]:
    """Connected pieces (8-connected) of ridge pixels of the same direction bin: the pixels, in
    raster order, are given by their bins and their 8-neighbour ``pairs`` (see
    :func:`pcmapq.features.pixels.neighbour_pairs`); returns each pixel's piece, numbered from 0
    by bin, then in raster order of the piece's first pixel, and the number of pieces."""
    a, b = pairs
    same = bins[a] == bins[b]
    count, label = connected(len(bins), a[same], b[same])
    # pieces are numbered by their first pixel; number them by bin first
    first_bin = np.zeros(count, np.int64)
    first_bin[label] = bins
    rank = np.empty(count, np.int64)
    rank[np.lexsort((np.arange(count), first_bin))] = np.arange(count)
    return rank[label], count


def pieces(mask: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Straight pieces of the ridge lines, in pixels (u, v): (N, 4) ``u0, v0, u1, v1``.

    The ridge pixels are split by their local direction into 30 degree bins; each connected run
    of pixels of one bin is a piece, fitted by the principal axis of its pixels and spanning
    them (to the outer edges of its end pixels). Two partitions, the second shifted by half a
    bin, are used together, so a wall whose direction lies on a bin border is still whole in one
    of them; the duplicates are merged later. A piece follows the ridge pixels themselves: it
    neither jumps between parallel walls nor cuts across a curve, and a wall wavy by a pixel
    stays one piece as long as its direction stays within the bin.
    """
    v, u, index = flat_index(mask)
    pairs = neighbour_pairs(index, mask.shape[1])
    theta = direction[v, u]
    out = []
    for offset in (0.0, 0.5):
        bins = np.floor(np.mod(theta * (_BINS / np.pi) + offset, _BINS)).astype(np.int32)
        lab, n = _label(bins, pairs)
        count = np.bincount(lab, minlength=n).astype(np.float64)
        cu = np.bincount(lab, u, n) / count
        cv = np.bincount(lab, v, n) / count
        du, dv = u - cu[lab], v - cv[lab]
        suu = np.bincount(lab, du * du, n)
        svv = np.bincount(lab, dv * dv, n)
        suv = np.bincount(lab, du * dv, n)
        angle = 0.5 * np.arctan2(2 * suv, suu - svv)  # principal axis of each piece
        eu, ev = np.cos(angle), np.sin(angle)
        t = du * eu[lab] + dv * ev[lab]
        lo, hi = np.full(n, np.inf), np.full(n, -np.inf)
        np.minimum.at(lo, lab, t)
        np.maximum.at(hi, lab, t)
        lo, hi = lo - 0.5, hi + 0.5  # pixel centres to pixel edges
        out.append(np.column_stack([cu + lo * eu, cv + lo * ev, cu + hi * eu, cv + hi * ev]))
    return np.concatenate(out).reshape(-1, 4)
