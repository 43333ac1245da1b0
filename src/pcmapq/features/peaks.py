"""The h-maxima of an image (the rooms' seeds): scikit-image's ``h_maxima``, the same cells, with
its grayscale reconstruction done by the hybrid algorithm of Vincent (1993) in a compiled loop.

``skimage.morphology.reconstruction`` sorts every value of the seed and the mask (2N values) and
then walks them in order; the reconstruction by dilation is one image whatever the algorithm
(every value is one of the seed's or the mask's, found by maxima and minima alone), so two raster
scans and a queue give it in linear time, with no sort.
The arithmetic around it (the seed ``image - h - resolution``, the residue ``image - rec``) is
scikit-image's, in the image's own float type, so the cells are the same.
"""

from __future__ import annotations

import numba
import numpy as np


def h_maxima(image: np.ndarray, h: float) -> np.ndarray:
    """(rows, cols) uint8: 1 on the maxima of the float image (rows, cols) that rise at least
    ``h`` above every path to a higher maximum, and on the global maxima; 8-connected. As
    ``skimage.morphology.h_maxima(image, h)`` for a float image and a float ``h`` > 0."""
    if h > np.ptp(image):
        return np.zeros(image.shape, dtype=np.uint8)
    h = image.dtype.type(h)
    resolution = 2 * np.finfo(image.dtype).resolution * np.abs(image)
    rebuilt = image - h - resolution  # the seed, a new array: reconstructed in place
    _reconstruct(rebuilt, np.ascontiguousarray(image))
    return ((image - rebuilt) >= h).astype(np.uint8)


def reconstruction(seed: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """The grayscale reconstruction by dilation of ``seed`` under ``mask`` (both (rows, cols),
    one float type, seed <= mask everywhere), 8-connected: ``skimage.morphology.reconstruction(
    seed, mask)``."""
    out = np.array(seed, order="C")  # one copy: the caller's seed is left as it was
    _reconstruct(out, np.ascontiguousarray(mask, dtype=out.dtype))
    return out


@numba.njit(cache=True, nogil=True)
def _reconstruct(rec: np.ndarray, mask: np.ndarray) -> None:
    """Vincent's hybrid reconstruction by dilation, in place of the seed ``rec``: a raster scan
    and an anti-raster scan each propagate the maximum from the half of the 8 neighbours already
    scanned (clipped by the mask); the cells the second scan leaves able to raise a neighbour go
    on a queue (each at most once at a time), which propagates until nothing changes."""
    rows, cols = rec.shape
    for r in range(rows):
        for c in range(cols):
            v = rec[r, c]
            if r > 0:
                if c > 0:
                    v = max(v, rec[r - 1, c - 1])
                v = max(v, rec[r - 1, c])
                if c < cols - 1:
                    v = max(v, rec[r - 1, c + 1])
            if c > 0:
                v = max(v, rec[r, c - 1])
            rec[r, c] = min(v, mask[r, c])
    size = rows * cols
    queue = np.empty(size, np.int64)
    queued = np.zeros(size, np.bool_)
    head = 0
    count = 0
    for r in range(rows - 1, -1, -1):
        for c in range(cols - 1, -1, -1):
            v = rec[r, c]
            if r < rows - 1:
                if c < cols - 1:
                    v = max(v, rec[r + 1, c + 1])
                v = max(v, rec[r + 1, c])
                if c > 0:
                    v = max(v, rec[r + 1, c - 1])
            if c < cols - 1:
                v = max(v, rec[r, c + 1])
            v = min(v, mask[r, c])
            rec[r, c] = v
            raises = False
            if r < rows - 1:
                for dc in (-1, 0, 1):
                    q = c + dc
                    if 0 <= q < cols and rec[r + 1, q] < v and rec[r + 1, q] < mask[r + 1, q]:
                        raises = True
            if c < cols - 1 and rec[r, c + 1] < v and rec[r, c + 1] < mask[r, c + 1]:
                raises = True
            if raises:
                p = r * cols + c
                queue[(head + count) % size] = p
                queued[p] = True
                count += 1
    while count > 0:
        p = queue[head]
        head = (head + 1) % size
        count -= 1
        queued[p] = False
        r, c = p // cols, p % cols
        v = rec[r, c]
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                qr, qc = r + dr, c + dc
                if (dr == 0 and dc == 0) or qr < 0 or qr >= rows or qc < 0 or qc >= cols:
                    continue
                w = rec[qr, qc]
                m = mask[qr, qc]
                if w < v and w != m:
                    rec[qr, qc] = min(v, m)
                    q = qr * cols + qc
                    if not queued[q]:
                        queue[(head + count) % size] = q
                        queued[q] = True
                        count += 1
