"""Raster morphology in cells: the one Euclidean distance transform every module uses, and the
disc that closings use."""

from __future__ import annotations

import cv2
import numpy as np

#: Where :func:`precise_distance` writes its output: this many bytes past a multiple of
#: ALIGN bytes (see there).
ALIGN, OFFSET = 64, 16


def distance_to(mask: np.ndarray) -> np.ndarray:
    """Euclidean distance, in cells, from every cell to the nearest true cell of ``mask``.

    mask: (rows, cols) bool (or 0/nonzero). Returns (rows, cols) float32, inf everywhere when
    ``mask`` has no true cell. OpenCV's precise transform (:func:`precise_distance`, an exact
    Euclidean transform computed in float32): it agrees with SciPy's
    ``distance_transform_edt`` in float64 up to float32 rounding; a cell hundreds of cells from
    the nearest wall may get the next squared distance (a relative error near 1e-6).
    """
    if not mask.any():
        return np.full(mask.shape, np.inf, dtype=np.float32)
    return precise_distance(np.logical_not(mask).view(np.uint8))


def precise_distance(image: np.ndarray) -> np.ndarray:
    """``cv2.distanceTransform(image, DIST_L2, DIST_MASK_PRECISE)``: (rows, cols) float32
    distance, in cells, from every cell to the nearest zero cell of the uint8 ``image``, the
    same values wherever memory puts them.

    OpenCV hands an image of fewer than 2^14 cells (or any image, on one OpenCV thread) to
    IPP, whose result depends in its last bit on the output's address modulo 32 bytes; a
    larger one on more threads goes to OpenCV's own transform, which does not. The output is
    therefore always written at one such address, OFFSET bytes past a multiple of ALIGN: where
    a large allocation lies (16 bytes past a page), so that those keep their values."""
    rows, cols = image.shape
    raw = np.empty(rows * cols * 4 + ALIGN, np.uint8)
    start = (OFFSET - raw.ctypes.data) % ALIGN
    out = raw[start:start + rows * cols * 4].view(np.float32).reshape(rows, cols)
    cv2.distanceTransform(image, cv2.DIST_L2, cv2.DIST_MASK_PRECISE, dst=out)
    return out


def disc(radius: float) -> np.ndarray:
    """OpenCV's elliptic structuring element of ``radius`` cells, rounded (at least 1):
    (2 r + 1, 2 r + 1) uint8. Not quite the Euclidean disc (:func:`pcmapq.features.base.disk`):
    OpenCV rasterises an ellipse, whose rows next to the centre row are as wide as it."""
    r = max(1, int(round(radius)))
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))


def outline(mask: np.ndarray, width: float, edge_is_outside: bool = True) -> np.ndarray:
    """The cells of ``mask`` (bool) within ``width`` cells of a cell outside it (a cell next to
    one outside is 1 cell from it): a filled block becomes its band of that width, a wall up to
    twice as thick stays whole. Cells at the image's border count as next to the outside, or
    (``edge_is_outside`` False) the image goes on beyond its border as it is there. One byte a
    cell: the mask less its erosion by :func:`disc` of ``width``."""
    mask = np.asarray(mask, dtype=bool)
    border = cv2.BORDER_CONSTANT if edge_is_outside else cv2.BORDER_REPLICATE
    inner = cv2.erode(mask.view(np.uint8), disc(width), borderType=border, borderValue=0)
    return mask & (inner == 0)


def reaching_border(mask: np.ndarray) -> np.ndarray:
    """The cells of ``mask`` (bool) in 8-connected regions that reach the image's border: one
    flood fill from a ring of true cells around the image. One byte a cell."""
    ring = np.pad(np.asarray(mask, dtype=bool), 1, constant_values=True).astype(np.uint8)
    cv2.floodFill(ring, None, (0, 0), 2, flags=8)
    return ring[1:-1, 1:-1] == 2

