"""SIFT on the local-entropy image, in metres.

As in the paper, a binary map is first turned into a grey image of its local entropy: with
``p`` the occupied fraction in a Gaussian window of ``window`` metres (on the working image, see
:mod:`pcmapq.features.base`), ``H = -p log2 p - (1 - p) log2 (1 - p)`` bits, in [0, 1], scaled
to uint8. ``cv2.SIFT`` runs on it with fixed parameters; the fixed working resolution makes its
scales metric, and keypoints wider than ``max_size`` metres (room-sized blobs) are dropped.
Hysteresis: SIFT runs twice, a loose run (support contrast, laxer edge test) giving the
features and a strict run marking the strong ones, which must also be the strongest within
``radius`` metres. SIFT returns one keypoint per dominant orientation: one is kept per place.
``strength`` is the SIFT response (the DoG contrast of the keypoint, image scaled to [0, 1]).

Matching: pairs within the threshold in metres are candidates; the cost is the descriptor
(L2) distance, so among nearby keypoints the most alike are paired.
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy.spatial import cKDTree

from pcmapq.features.base import (
    Candidates,
    Detector,
    Features,
    empty_features,
    gaussian,
    point_candidates,
    sorted_features,
    suppress,
    working_image,
)
from pcmapq.grid import MetricGrid

#: Keypoints closer than this are one keypoint seen with several orientations, metres.
_DUPLICATE = 0.05


def entropy(image: np.ndarray, window_px: float) -> np.ndarray:
    """Local binary entropy of an occupied-fraction image, in bits.

    Parameters
    ----------
    image : (rows, cols) float32, occupied fraction in [0, 1].
    window_px : sigma of the Gaussian window, pixels.

    Returns
    -------
    (rows, cols) float32 entropy in [0, 1] bits.
    """
    p = np.clip(gaussian(image, window_px), 1e-7, 1 - 1e-7)
    h = -p * np.log2(p) - (1 - p) * np.log2(1 - p)
    return np.where((p <= 1e-7) | (p >= 1 - 1e-7), 0.0, h).astype(np.float32)


def detect(occupied: np.ndarray, grid: MetricGrid, *, resolution: float = 0.05,
           closing: float = 0.1, window: float = 0.15, threshold: float = 0.025,
           support: float = 0.5, radius: float = 0.3, octave_layers: int = 3,
           edge: float = 10.0, sigma: float = 1.6, max_size: float = 1.0,
           support_edge: float = 2.0, precise: bool = False) -> Features:
    """SIFT keypoints and descriptors of the entropy image of a binary map.

    Parameters
    ----------
    occupied : (rows, cols) bool raster on ``grid``, walls true.
    grid : the raster's grid; features are returned in its metric frame.
    resolution : working cell size, metres.
    closing : closing radius, metres (see :func:`pcmapq.features.base.working_image`).
    window : sigma of the entropy window, metres.
    threshold : detection threshold on the SIFT response (DoG contrast, image in [0, 1]).
    support : support threshold, as a fraction of ``threshold``.
    radius : only the strongest keypoint within this radius is kept, metres.
    max_size : largest keypoint diameter kept, metres: room-sized blobs are not local
        features, and whether SIFT finds them depends on the whole room.
    support_edge : the support-level run accepts edge-like keypoints up to this multiple of
        ``edge``: a keypoint near the edge test's limit is found on one side only.
    octave_layers, edge, sigma : ``cv2.SIFT_create``'s nOctaveLayers, edgeThreshold and sigma
        (pixels of the working image).

    Returns
    -------
    Features with ``strength`` the SIFT response and ``descriptors`` (N, 128) float32.
    """
    image, work = working_image(occupied, grid, resolution, closing)
    grey = np.round(entropy(image, window / resolution) * 255).astype(np.uint8)
    # OpenCV drops keypoints below contrastThreshold / nOctaveLayers
    strict = _keypoints(grey, octave_layers, threshold * octave_layers, edge, sigma, max_size,
                        resolution, precise)
    loose = _keypoints(grey, octave_layers, support * threshold * octave_layers,
                       support_edge * edge, sigma, max_size, resolution, precise)
    if loose is None:
        return empty_features(with_descriptors=True)
    uv, value, desc = loose
    xy = work.pixels_to_xy(uv)
    strong = np.zeros(len(xy), dtype=bool)
    if strict is not None:  # the loose keypoints the strict run finds too
        near = cKDTree(work.pixels_to_xy(strict[0])).query(xy, distance_upper_bound=_DUPLICATE)
        strong = np.isfinite(near[0])
    # one keypoint per place (SIFT repeats it per orientation); strong ones are also the
    # strongest within radius. Support ones are not suppressed by neighbours, so a keypoint
    # suppressed by a slightly stronger neighbour on one side still confirms the other's.
    keep = suppress(xy, value, _DUPLICATE)
    strong &= suppress(xy, value, radius)
    return sorted_features(xy[keep], value[keep], strong[keep],
                           descriptors=desc[keep].astype(np.float32))


def _keypoints(grey: np.ndarray, layers: int, contrast: float, edge: float, sigma: float,
               max_size: float, resolution: float, precise=False
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """SIFT on ``grey``: pixel positions (N, 2), responses (N,) and descriptors (N, 128) of
    the keypoints at most ``max_size`` metres across; None when there are none."""
    sift = cv2.SIFT_create(nOctaveLayers=layers, contrastThreshold=contrast,
                           edgeThreshold=edge, sigma=sigma, enable_precise_upscale=precise)
    keypoints, desc = sift.detectAndCompute(grey, None)
    if not keypoints:
        return None
    small = np.array([k.size for k in keypoints]) * resolution <= max_size
    if not small.any():
        return None
    uv = np.array([k.pt for k in keypoints], dtype=np.float64)
    value = np.array([k.response for k in keypoints], dtype=np.float64)
    return uv[small], value[small], desc[small]


#: Largest L2 distance between two OpenCV SIFT descriptors (each normalised to 512).
DESCRIPTOR_MAX = 512.0 * np.sqrt(2.0)

def candidates(truth: Features, map_: Features, threshold: float) -> Candidates:
    """Keypoint pairs within ``threshold`` metres; cost = the mean of their distance over the
    threshold and their descriptor distance over its largest value, so that among nearby
    candidates the descriptor decides, and no far pair is taken for a near one."""
    i, j, dist, disp = point_candidates(truth, map_, threshold)
    desc = np.linalg.norm(truth.descriptors[i] - map_.descriptors[j], axis=1)
    return i, j, 0.5 * (dist + np.minimum(desc / DESCRIPTOR_MAX, 1.0)), disp


DETECTOR = Detector("sift", detect, candidates)
