"""What every detector shares: the Features type, the Detector record, and their helpers.

Detectors never look at the input raster directly. They see the walls' centre lines drawn as a
band of fixed width on a *working grid* (same origin and yaw as the input grid, a fixed cell
size in metres; see :mod:`pcmapq.features.walls`), so a plan drawn with thin or thick walls, as
outlines, at 0.025 m or at 0.05 m gives the same working image up to rasterisation noise, and
every length parameter (all in metres) means the same number of working pixels.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import cv2
import numpy as np
from scipy.spatial import cKDTree

from pcmapq.core.bounds import nonzero_window
from pcmapq.core.errors import InputError
from pcmapq.features.walls import WallImage

#: Candidate pairs: truth indices, map indices, costs, displacements (M, 2) in metres.
Candidates = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class Features:
    """Features of one map, in the metric frame of the grid they were detected on.

    xy: (N, 2) feature positions, metres.
    strength: (N,) detector response (Harris response, segment length in metres, SIFT response).
    strong: (N,) bool, true above the detection threshold; the others are above the lower
        support threshold only: they may confirm a strong feature of the other map but are
        never counted on their own.
    descriptors: SIFT descriptors (N, 128) float32, else None.
    segments: Hough segments (N, 4) ``x0, y0, x1, y1`` in metres, else None.
    labels: rooms: (rows, cols) int32 raster of the rooms' cells on the detector's grid, 0 no
        room, feature k at k + 1; else None.
    doors: rooms: (D, 5) the doors between them: the two rooms (feature indices, the smaller
        first), the door's x, y (metres) and width (metres); else None.
    bounding: rooms: the share of the walls' cells next to a room, in [0, 1]; else None.
    """

    xy: np.ndarray
    strength: np.ndarray
    strong: np.ndarray
    descriptors: np.ndarray | None = None
    segments: np.ndarray | None = None
    labels: np.ndarray | None = None
    doors: np.ndarray | None = None
    bounding: float | None = None

    def __len__(self) -> int:
        return len(self.xy)

    def counted_where(self, keep: np.ndarray) -> Features:
        """The same features with only those where ``keep`` (N,) is true left strong: the
        others may still confirm a feature of the other map but are not counted."""
        return replace(self, strong=self.strong & keep)


@dataclass(frozen=True)
class Detector:
    """A feature detector: how to find features, which pairs of features may match, and the
    parameters of both.

    detect: ``detect(walls, params) -> Features``; ``walls`` is a
        :class:`~pcmapq.features.walls.WallImage`, the walls as every detector sees them, and
        ``params`` an instance of ``params``.
    candidates: ``candidates(truth, map_, threshold, params) -> (i, j, cost, displacement)``:
        the pairs (truth ``i``, map ``j``) that may match under ``threshold`` metres, their
        costs in [0, 1] (0 a perfect pair, 1 the worst acceptable one) and displacements
        (M, 2) in metres, from the truth feature to the map feature.
    params: the detector's parameters, a frozen dataclass whose field defaults are the
        documented ones (``params()``), lengths in metres.
    by_default: whether an evaluation runs it when no detectors are named.
    min_truth: the fewest features (counted or not) the truth must have for the detector to
        have anything to find; with fewer its three scores are undefined (rooms: 2, since a
        place that is one room has no rooms to tell apart; 0: no such minimum).
    noun: what one feature is called in a sentence ("corner", "room").
    nothing_to_find: why the truth's features leave the detector nothing to find though
        there are ``min_truth`` of them (rooms: pockets its walls close off, not rooms), its
        three scores then undefined; None when they do not.
    """

    name: str
    detect: Callable[[WallImage, Any], Features]
    candidates: Callable[[Features, Features, float, Any], Candidates]
    params: type
    by_default: bool = True
    min_truth: int = 0
    noun: str = "feature"
    nothing_to_find: Callable[[Features], str | None] = lambda truth: None

    def checked(self, params: Any = None) -> Any:
        """``params``, or the defaults when None; InputError when they are not this
        detector's."""
        if params is None:
            return self.params()
        if not isinstance(params, self.params):
            raise InputError(f"detector {self.name!r} takes {self.params.__module__}."
                             f"{self.params.__qualname__}, not {type(params).__qualname__}")
        return params


def empty_features(with_descriptors: bool = False, with_segments: bool = False) -> Features:
    """Features with no feature in them."""
    return Features(
        xy=np.zeros((0, 2)),
        strength=np.zeros(0),
        strong=np.zeros(0, dtype=bool),
        descriptors=np.zeros((0, 128), dtype=np.float32) if with_descriptors else None,
        segments=np.zeros((0, 4)) if with_segments else None,
    )


def sorted_features(
    xy: np.ndarray,
    strength: np.ndarray,
    strong: np.ndarray,
    descriptors: np.ndarray | None = None,
    segments: np.ndarray | None = None,
) -> Features:
    """Features in a canonical order (by x, then y, then strength), so the output depends on
    the features only, not on the order a detector found them in."""
    order = np.lexsort((strength, xy[:, 1], xy[:, 0])) if len(xy) else np.zeros(0, dtype=int)
    return Features(
        xy=np.asarray(xy, dtype=np.float64)[order].reshape(-1, 2),
        strength=np.asarray(strength, dtype=np.float64)[order],
        strong=np.asarray(strong, dtype=bool)[order],
        descriptors=None if descriptors is None else descriptors[order],
        segments=None if segments is None else np.asarray(segments, np.float64)[order],
    )


def disk(radius_px: float) -> np.ndarray:
    """A disk-shaped uint8 structuring element of ``radius_px`` pixels (at least 3x3)."""
    r = max(1, int(round(radius_px)))
    v, u = np.mgrid[-r : r + 1, -r : r + 1]
    return (u * u + v * v <= radius_px * radius_px + 0.5).astype(np.uint8)


def gaussian_reach(sigma_px: float) -> int:
    """How many pixels away :func:`gaussian` looks: its kernel's half-width, 4 sigma."""
    return int(np.ceil(4 * sigma_px))


def gaussian(image: np.ndarray, sigma_px: float) -> np.ndarray:
    """Gaussian blur with ``sigma_px`` pixels, kernel to 4 sigma, reflected borders."""
    if sigma_px <= 0:
        return image
    k = 2 * gaussian_reach(sigma_px) + 1
    return cv2.GaussianBlur(image, (k, k), sigma_px, borderType=cv2.BORDER_REFLECT)


#: Cells of a strip of :func:`by_strips`: strips of a few MB keep a step's temporaries in the
#: CPU's cache.
STRIP_CELLS = 1 << 21


def by_strips(image: np.ndarray, halo: int, fn: Callable[[np.ndarray], tuple[np.ndarray, ...]],
              rows: int | None = None) -> tuple[np.ndarray, ...]:
    """``fn(image)`` for an ``fn`` that looks no farther than ``halo`` cells (reflected borders
    stay the image's own): the same arrays, cell for cell, computed on the window of cells
    within ``halo`` of a nonzero cell only (the others get what ``fn`` gives an all-zero image),
    in strips of ``rows`` rows (by default :data:`STRIP_CELLS` cells, at least four halos),
    each with ``halo`` rows above and below it, in the memory of one strip. ``fn`` returns
    arrays of the shape of its input."""
    window = nonzero_window(image, halo)
    if window == (0, image.shape[0], 0, image.shape[1]):
        return _strips(image, halo, fn, rows)
    blank = tuple(a[halo, halo] for a in fn(np.zeros((2 * halo + 1,) * 2, image.dtype)))
    out = tuple(np.full(image.shape, value, value.dtype) for value in blank)
    if window is not None:
        lo, hi, left, right = window
        for whole, part in zip(out, _strips(image[lo:hi, left:right], halo, fn, rows),
                               strict=True):
            whole[lo:hi, left:right] = part
    return out


def _strips(image: np.ndarray, halo: int, fn: Callable[[np.ndarray], tuple[np.ndarray, ...]],
            rows: int | None) -> tuple[np.ndarray, ...]:
    """:func:`by_strips` over the whole of ``image``."""
    if rows is None:
        rows = max(4 * halo, STRIP_CELLS // max(image.shape[1], 1))
    if image.shape[0] <= rows + 2 * halo:
        return fn(image)
    out: tuple[np.ndarray, ...] = ()
    for top in range(0, image.shape[0], rows):
        lo, hi = max(0, top - halo), min(image.shape[0], top + rows + halo)
        got = fn(image[lo:hi])
        if not out:
            out = tuple(np.empty(image.shape, a.dtype) for a in got)
        for whole, part in zip(out, got, strict=True):
            whole[top:top + rows] = part[top - lo:top - lo + min(rows, image.shape[0] - top)]
    return out


def suppress(xy: np.ndarray, strength: np.ndarray, radius: float) -> np.ndarray:
    """Non-maximum suppression of points: keep a point (N, 2, metres) unless a stronger one
    lies within ``radius`` metres (ties: the later one in canonical order is dropped).

    Returns the (N,) bool mask of kept points.
    """
    keep = np.ones(len(xy), dtype=bool)
    if len(xy) < 2 or radius <= 0:
        return keep
    pairs = cKDTree(xy).query_pairs(radius, output_type="ndarray")
    rank = np.empty(len(xy), dtype=np.int64)
    rank[np.lexsort((xy[:, 1], xy[:, 0], -strength))] = np.arange(len(xy))  # 0 = strongest
    a, b = pairs[:, 0], pairs[:, 1]
    keep[np.where(rank[a] > rank[b], a, b)] = False
    return keep


def point_candidates(truth: Features, map_: Features, threshold: float) -> Candidates:
    """Pairs of point features within ``threshold`` metres, at least one of them strong.

    cost = Euclidean distance / threshold; displacement = map xy - truth xy, metres.
    """
    if len(truth) == 0 or len(map_) == 0:
        return no_candidates()
    dist = cKDTree(truth.xy).sparse_distance_matrix(
        cKDTree(map_.xy), threshold, output_type="ndarray"
    )
    i, j = dist["i"].astype(np.int64), dist["j"].astype(np.int64)
    keep = truth.strong[i] | map_.strong[j]
    i, j = i[keep], j[keep]
    return i, j, dist["v"][keep] / threshold, map_.xy[j] - truth.xy[i]


def no_candidates() -> Candidates:
    """The empty candidate set."""
    return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 2))
