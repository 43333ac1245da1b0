"""SIFT on the local-entropy image, in metres.

As in the paper, a binary map is first turned into a grey image of its local entropy: with
``p`` the occupied fraction in a Gaussian window of ``window`` metres (on the working image, see
:mod:`pcmapq.features.base`), ``H = -p log2 p - (1 - p) log2 (1 - p)`` bits, in [0, 1].

Keypoints are the extrema of SIFT's difference-of-Gaussians (DoG) scale space of that image,
built as ``cv2.SIFT`` builds it (``octave_layers`` layers per octave, base blur ``sigma``
pixels of the working image; no doubled first octave), so the fixed working resolution makes
the scales metric. The extrema are found by :mod:`pcmapq.features.scale_space` rather than by
``cv2.SIFT``, which loses keypoints in two ways that come and go with a half-cell shift of the
map: its sub-pixel refinement drops an extremum whose quadratic fit keeps stepping between two
samples (the extremum lies about half a sample from both), and an extremum at the scale limit
of an octave can fail the test in both octaves, which sample it differently. Here every sample
that is an extremum of its 26 neighbours is a keypoint, refined by one quadratic step clipped
to half a sample in space and scale, and each octave has one layer more than ``cv2.SIFT`` so
that consecutive octaves share a searched DoG layer. Its response is the refined DoG contrast
(image in [0, 1]); keypoints wider than ``max_size`` metres (room-sized blobs) are dropped.
``cv2.SIFT`` computes the descriptors of these keypoints, upright: features are detected on
rasters in the truth's frame, after alignment, so rotation invariance buys nothing, and SIFT's
dominant orientation flips between the walls of a corner (on a plan drawn half a cell shifted,
many keypoints turn by tens of degrees, and their descriptors become as unlike as those of
unrelated keypoints).

Hysteresis: a keypoint is kept at ``support * threshold`` response and an edge ratio under
``support_edge * edge``; it is strong at ``threshold`` and under ``edge``, if it is also the
strongest keypoint within ``radius`` metres. Keypoints closer than ``duplicate`` (0.1 m, one
sample of the octave most keypoints are found in; an extremum shared by two octaves is found
twice) are one, the strongest. ``strength`` is the response.

Matching: pairs within the threshold in metres are candidates if their descriptors are alike:
an L2 distance at most ``descriptor_gate``, by default the descriptors' own length (512; an
angle of at most 60 degrees, cosine >= 0.5). The same keypoint on a re-drawn plan stays under
about half of that; in a map built from drifted poses each wall is smeared over a band, and the
keypoints of the smear that lie within the threshold of a truth keypoint no longer look like
it. Without this gate any keypoint within the threshold would match, however unlike, and a map
whose poses are off by tens of metres would keep a high SIFT quality. The cost is the mean of
the distance over the threshold and the descriptor distance over the gate, so among nearby
alike keypoints the most alike are paired.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from pcmapq.features.base import (
    Candidates,
    Detector,
    Features,
    empty_features,
    gaussian,
    point_candidates,
    sorted_features,
    suppress,
)
from pcmapq.features.scale_space import Extrema, extrema, octave_count
from pcmapq.features.walls import WallImage

#: Length of an OpenCV SIFT descriptor (L2 norm; its entries are non-negative).
DESCRIPTOR_NORM = 512.0


@dataclass(frozen=True)
class Params:
    """Parameters of the SIFT detector and of its matching rule.

    window: sigma of the entropy window, metres.
    threshold: detection threshold on the response (DoG contrast, image in [0, 1]).
    support: support threshold, as a fraction of ``threshold``.
    radius: a strong keypoint must be the strongest within this radius, metres.
    octave_layers: DoG layers searched per octave (``cv2.SIFT_create``'s nOctaveLayers).
    edge: edge test: a keypoint whose DoG principal curvatures differ by a ratio of ``edge``
        or more is edge-like, not strong (``cv2.SIFT_create``'s edgeThreshold).
    sigma: blur of the first scale, pixels of the working image (``cv2.SIFT_create``'s sigma).
    max_size: largest keypoint diameter kept, metres: room-sized blobs are not local features,
        and whether they are found depends on the whole room.
    support_edge: support-level keypoints may be edge-like up to a ratio of this multiple of
        ``edge``: a keypoint near the edge test's limit passes it on one side only.
    duplicate: keypoints closer than this are one keypoint, the strongest, metres (one sample
        of the octave most keypoints are found in; an extremum shared by two octaves is found
        twice).
    descriptor_gate: largest descriptor distance (L2) of an acceptable pair; by default the
        descriptors' own length :data:`DESCRIPTOR_NORM`, i.e. an angle of at most 60 degrees
        between them (cosine >= 0.5). The same keypoint on a re-drawn plan (half-cell shift,
        turned and warped back, 0.025 vs 0.05 m, LiDAR faces) stays under about half of it;
        unrelated keypoints are mostly beyond it.
    """

    window: float = 0.15
    threshold: float = 0.025
    support: float = 0.5
    radius: float = 0.3
    octave_layers: int = 3
    edge: float = 10.0
    sigma: float = 1.6
    max_size: float = 1.0
    support_edge: float = 2.0
    duplicate: float = 0.1
    descriptor_gate: float = DESCRIPTOR_NORM


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
    p = np.asarray(gaussian(image, window_px), dtype=np.float32)
    at = np.flatnonzero((p > 1e-7) & (p < 1 - 1e-7))  # 0 bits where the window is one state
    pa = p.ravel()[at]
    qa = 1 - pa
    h = np.zeros(p.shape, dtype=np.float32)
    h.ravel()[at] = -(np.log2(pa) * pa + np.log2(qa) * qa)
    return h


def detect(walls: WallImage, params: Params) -> Features:
    """SIFT keypoints and descriptors of the entropy image of a binary map, seen as ``walls``
    (see :func:`pcmapq.features.walls.wall_image`), in the metric frame of its grid:
    ``strength`` is the response and ``descriptors`` (N, 128) float32."""
    p, work = params, walls.grid
    resolution = work.resolution
    ent = entropy(walls.image, p.window / resolution)
    octaves = octave_count(ent.shape, p.sigma, p.octave_layers, p.max_size / resolution)
    if octaves < 1:
        return empty_features(with_descriptors=True)
    kp = extrema(ent, p.sigma, p.octave_layers, octaves, 0.5 * p.support * p.threshold)
    size = kp.size * resolution
    response = np.abs(kp.contrast)

    def edge_ok(r: float) -> np.ndarray:  # Lowe's test: tr^2 / det < (r + 1)^2 / r
        return kp.edge_ratio < (r + 1.0) ** 2 / r

    keep = ((size <= p.max_size) & (response >= p.support * p.threshold)
            & edge_ok(p.support_edge * p.edge))
    strong = (response >= p.threshold) & edge_ok(p.edge)
    kp, response, strong = kp.where(keep), response[keep], strong[keep]
    if not len(kp):
        return empty_features(with_descriptors=True)
    xy = work.pixels_to_xy(kp.pt)
    # one keypoint per place; strong ones are also the strongest within radius. Support ones
    # are not suppressed by neighbours, so a keypoint suppressed by a slightly stronger
    # neighbour on one side still confirms the other's.
    once = suppress(xy, response, p.duplicate)
    strong &= suppress(xy, response, p.radius)
    kp, xy, response, strong = kp.where(once), xy[once], response[once], strong[once]
    grey = np.round(ent * 255).astype(np.uint8)
    desc = descriptors(grey, kp, response, p.octave_layers, p.sigma)
    return sorted_features(xy, response, strong, descriptors=desc)


def descriptors(grey: np.ndarray, kp: Extrema, response: np.ndarray, layers: int,
                sigma: float) -> np.ndarray:
    """Upright ``cv2.SIFT`` descriptors (N, 128) float32 of the extrema ``kp`` (found with
    ``layers`` and ``sigma``, pixels of ``grey``) on the uint8 image ``grey``: every keypoint's
    orientation is 0 (the grid's +u axis), as both maps are in the truth's frame when features
    are detected."""
    octave = kp.octave + (kp.layer << 8) + (np.round((kp.xi + 0.5) * 255).astype(np.int64) << 16)
    points = [cv2.KeyPoint(float(u), float(v), float(s), 0.0, float(r), int(oc))
              for (u, v), s, r, oc in zip(kp.pt, kp.size, response, octave, strict=True)]
    sift = cv2.SIFT_create(nOctaveLayers=layers, sigma=sigma)
    got, desc = sift.compute(grey, points)
    if len(got) != len(points):
        raise RuntimeError("cv2.SIFT dropped keypoints it was given")
    return np.asarray(desc, dtype=np.float32).reshape(-1, 128)


def candidates(truth: Features, map_: Features, threshold: float, params: Params) -> Candidates:
    """Keypoint pairs within ``threshold`` metres whose descriptors are alike (L2 distance at
    most ``params.descriptor_gate``); cost = the mean of their distance over the threshold and
    their descriptor distance over the gate, so that among nearby alike keypoints the most
    alike are paired, and no far pair is taken for a near one."""
    gate = params.descriptor_gate
    i, j, dist, disp = point_candidates(truth, map_, threshold)
    desc = np.linalg.norm(truth.descriptors[i] - map_.descriptors[j], axis=1)
    alike = desc <= gate
    return i[alike], j[alike], 0.5 * (dist[alike] + desc[alike] / gate), disp[alike]


DETECTOR = Detector("sift", detect, candidates, Params)
