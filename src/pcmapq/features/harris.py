"""Harris corners, in metres.

The working image (see :mod:`pcmapq.features.base`) is smoothed with a Gaussian of ``sigma``
metres, differentiated, and its structure tensor integrated with a Gaussian of ``integration``
metres. Derivatives are taken per metre and multiplied by ``sigma`` (scale normalisation), so
the response ``det - k trace^2`` is dimensionless and its threshold absolute: it does not depend
on the resolution or on what else is in the map. Corners are the local maxima within
``radius`` metres, refined to sub-pixel position. Wall ends (door jambs) are corners too.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from pcmapq.features.base import (
    Candidates,
    Detector,
    Features,
    by_strips,
    disk,
    gaussian,
    gaussian_reach,
    point_candidates,
    sorted_features,
    suppress,
)
from pcmapq.features.walls import WallImage


@dataclass(frozen=True)
class Params:
    """Parameters of the Harris detector.

    sigma: derivative (smoothing) scale, metres.
    integration: structure tensor integration scale, metres.
    k: Harris sensitivity, dimensionless.
    threshold: detection threshold on the scale-normalised response (dimensionless). An L corner
        of a 0.15 m wall scores about 5e-4, a T junction about 1e-4.
    support: support threshold, as a fraction of ``threshold``.
    radius: non-maximum suppression radius, metres.
    """

    sigma: float = 0.1
    integration: float = 0.2
    k: float = 0.05
    threshold: float = 4e-5
    support: float = 0.5
    radius: float = 0.3


def response(image: np.ndarray, resolution: float, sigma: float, integration: float,
             k: float) -> np.ndarray:
    """Scale-normalised Harris response of a float image whose cells are ``resolution`` m.

    Parameters
    ----------
    image : (rows, cols) float32.
    resolution : cell size, metres.
    sigma : derivative (smoothing) scale, metres.
    integration : structure tensor integration scale, metres.
    k : Harris sensitivity, dimensionless.

    Returns
    -------
    (rows, cols) float32 response, dimensionless.
    """
    smooth = gaussian(image, sigma / resolution)
    # Sobel 3x3 / 8 is a derivative per pixel; * sigma / resolution makes it per sigma
    scale = sigma / (8.0 * resolution)
    ix = cv2.Sobel(smooth, cv2.CV_32F, 1, 0, ksize=3, borderType=cv2.BORDER_REFLECT) * scale
    iy = cv2.Sobel(smooth, cv2.CV_32F, 0, 1, ksize=3, borderType=cv2.BORDER_REFLECT) * scale
    s = integration / resolution
    xx, yy, xy = gaussian(ix * ix, s), gaussian(iy * iy, s), gaussian(ix * iy, s)
    return xx * yy - xy * xy - k * (xx + yy) ** 2


def peaks(resp: np.ndarray, radius_px: float, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of ``resp`` over a disk of ``radius_px`` pixels, at least ``floor``.

    Returns sub-pixel (N, 2) pixel coordinates (u, v) and the (N,) peak values.
    """
    rows, cols = resp.shape
    # OpenCV's dilation ignores pixels beyond the border, as repeating the border would
    top = cv2.dilate(resp, disk(radius_px)).ravel()
    at = np.flatnonzero(resp >= floor)  # a few percent of the cells: test those only
    at = at[top[at] <= resp.ravel()[at]]
    v, u = np.divmod(at, cols)
    c = resp[v, u]
    # a parabola through the 3 values along each axis (the border repeated beyond it)
    left, right = resp[v, np.maximum(u - 1, 0)], resp[v, np.minimum(u + 1, cols - 1)]
    up, down = resp[np.maximum(v - 1, 0), u], resp[np.minimum(v + 1, rows - 1), u]
    du = 0.5 * (left - right) / np.minimum(left - 2 * c + right, -1e-12)
    dv = 0.5 * (up - down) / np.minimum(up - 2 * c + down, -1e-12)
    return np.column_stack([u + np.clip(du, -0.5, 0.5), v + np.clip(dv, -0.5, 0.5)]), c


def detect(walls: WallImage, params: Params) -> Features:
    """Harris corners of a binary map, seen as ``walls`` (see
    :func:`pcmapq.features.walls.wall_image`), in the metric frame of its grid; ``strength`` is
    the response."""
    work = walls.grid
    # the two blurs' reaches, the derivatives' pixel and one more
    reach = (gaussian_reach(params.sigma / work.resolution)
             + gaussian_reach(params.integration / work.resolution) + 2)
    resp, = by_strips(walls.image, reach, lambda strip: (response(
        strip, work.resolution, params.sigma, params.integration, params.k),))
    uv, value = peaks(resp, params.radius / work.resolution, params.support * params.threshold)
    xy = work.pixels_to_xy(uv)
    keep = suppress(xy, value, params.radius)  # plateaus give equal neighbouring maxima
    return sorted_features(xy[keep], value[keep], value[keep] >= params.threshold)


def candidates(truth: Features, map_: Features, threshold: float, params: Params) -> Candidates:
    """Pairs of corners within ``threshold`` metres; cost = distance / threshold (``params``
    hold no matching rule)."""
    return point_candidates(truth, map_, threshold)


DETECTOR = Detector("harris", detect, candidates, Params)
