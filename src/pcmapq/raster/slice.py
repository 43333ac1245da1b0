"""The wall band of a 3D cloud: the points between two heights above the floor, seen from above.

Clouds are assumed roughly gravity aligned (z up, as LiDAR SLAM maps are); a small tilt is
removed first. All heights are metres.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from pcmapq.core.frames import Levelling
from pcmapq.raster.levelling import level_rotation

#: Height histogram bin for finding the floor, metres.
FLOOR_BIN = 0.05
#: A histogram peak is "strong" when it holds at least this share of the largest bin's count.
PEAK_SHARE = 1.0 / 3.0
#: Points handled at once by :func:`wall_band`; the levelling looks at no more.
CHUNK = 2_000_000


def wall_band(points: np.ndarray, low: float = 0.3,
              high: float = 2.0) -> tuple[np.ndarray, Levelling]:
    """The points between ``low`` and ``high`` metres above the floor, projected onto the floor.

    points: (N, 3) metres, z roughly up, any float type (a file mapped by
    :mod:`pcmapq.io.clouds` included); rows with a non-finite coordinate are skipped. The cloud
    is first levelled with :func:`level_rotation` (a rotation about the horizontal axis only, so
    x, y and yaw are kept as far as the tilt allows), then the floor is found as
    :func:`floor_height` finds it. Returns (M, 2) float64 x, y in metres of the levelled cloud
    and the :class:`~pcmapq.core.frames.Levelling` that made it. Raises ValueError if there are no
    points or the band is empty.

    Up to CHUNK points this is computed in one go. A larger cloud is read CHUNK rows at a time
    (memory: a chunk, and about 2.5 times the band for the band and the points near it, however
    large the cloud): the levelling is found on every k-th point (k = ceil(N / CHUNK)), the
    floor and the band from all points, in two passes.
    """
    if not low < high:
        raise ValueError(f"wall band: low ({low} m) must be below high ({high} m)")
    if not isinstance(points, np.ndarray):
        points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"expected (N, 3) points, got shape {points.shape}")
    step = -(-len(points) // CHUNK)
    rotation = level_rotation(_finite_points(points[::step] if step > 1 else points))
    if len(points) <= CHUNK:
        levelled = _finite_points(points) @ rotation.T
        floor = floor_height(levelled)
        z = levelled[:, 2] - floor
        band = levelled[(z >= low) & (z <= high), :2]
    else:
        floor, band = _band_by_chunks(points, rotation, low, high)
    if len(band) == 0:
        raise ValueError(f"no points between {low} and {high} m above the floor "
                         f"(floor found at z = {floor:.2f} m)")
    return band, Levelling(rotation, floor)


def _band_by_chunks(points: np.ndarray, rotation: np.ndarray, low: float,
                    high: float) -> tuple[float, np.ndarray]:
    """:func:`wall_band`'s floor (metres) and band (M, 2) of a cloud (N, 3) larger than CHUNK,
    levelled by ``rotation``, in two passes over it: the height histogram (the floor's bin, as
    :func:`floor_height` finds it), then the heights in the floor's three bins (their median is
    the floor) and the points that may lie in the band whatever the floor within those bins,
    kept as the cloud holds them (float32 rows: half the memory of their levelled coordinates).
    Levelled coordinates are sums of products (one thread, no BLAS), the same in both passes
    and for the kept points again: each is computed from its own row alone."""
    bins, counts = _merged([_histogram(_bins(_turned(rows, rotation[2])))
                            for rows in _finite_chunks(points)])
    if len(bins) == 0:
        raise ValueError("no points")
    peak = _floor_bin(bins, counts)
    # The floor lies in bins peak - 1 .. peak + 1; one bin more each side covers rounding.
    lo, hi = (peak - 2) * FLOOR_BIN + low, (peak + 3) * FLOOR_BIN + high
    # rows go back to the cloud's own float type exactly (they were read from it)
    held = points.dtype if points.dtype in (np.float16, np.float32) else np.float64
    near, candidates = [], []  # per chunk: the floor bins' z; the candidates' rows
    for rows in _finite_chunks(points):
        z = _turned(rows, rotation[2])
        near.append(z[np.abs(_bins(z) - peak) <= 1])
        candidates.append(rows[(z >= lo) & (z <= hi)].astype(held, copy=False))
    floor = float(np.median(np.concatenate(near)))

    def inside(kept: np.ndarray) -> np.ndarray:
        z = _turned(kept.astype(np.float64), rotation[2]) - floor
        return (z >= low) & (z <= high)

    keep = [inside(kept) for kept in candidates]  # a byte a candidate
    band = np.empty((sum(int(np.count_nonzero(k)) for k in keep), 2))
    start = 0
    for i, kept in enumerate(candidates):
        rows = kept[keep[i]].astype(np.float64)
        candidates[i] = None  # each chunk's candidates freed once copied
        band[start:start + len(rows), 0] = _turned(rows, rotation[0])
        band[start:start + len(rows), 1] = _turned(rows, rotation[1])
        start += len(rows)
    return floor, band


def _finite_chunks(points: np.ndarray) -> Iterator[np.ndarray]:
    """The finite rows of ``points`` (N, 3, any float type), CHUNK at a time, as (n, 3)
    float64. Each chunk is overwritten by the next: keep copies."""
    rows = np.empty((CHUNK, 3))
    for start in range(0, len(points), CHUNK):
        part = rows[:min(CHUNK, len(points) - start)]
        part[...] = points[start:start + CHUNK]
        yield part if np.isfinite(part).all() else part[np.isfinite(part).all(axis=1)]


def _turned(rows: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """One levelled coordinate of points (n, 3): their dot product with ``axis`` (3,), a row
    of the levelling rotation."""
    out = rows[:, 0] * axis[0]
    out += rows[:, 1] * axis[1]
    out += rows[:, 2] * axis[2]
    return out


def floor_height(points: np.ndarray) -> float:
    """The floor's z, metres, of a levelled cloud (N, 3): the lowest strong peak of the height
    histogram.

    Heights are binned every FLOOR_BIN metres; a peak is a bin at least as full as both
    neighbours, strong if it holds at least PEAK_SHARE of the fullest bin's count. The floor is
    the median z of the lowest strong peak and its two neighbour bins. Ceilings and tables are
    higher peaks; sparse points below the floor (noise, reflections) are not strong peaks.
    """
    z = _finite_points(points)[:, 2]
    idx = _bins(z)
    return float(np.median(z[np.abs(idx - _floor_bin(*_histogram(idx))) <= 1]))


def _bins(z: np.ndarray) -> np.ndarray:
    """The FLOOR_BIN bin (int64 index) of each height z (n,), metres."""
    return np.floor(z / FLOOR_BIN).astype(np.int64)


def _histogram(idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sparse height histogram of bin indices (n,) of :func:`_bins`: the bins (sorted,
    int64) that hold points, and their counts."""
    if len(idx) == 0:
        return idx, idx
    lo = int(idx.min())
    if int(idx.max()) - lo > 4 * len(idx) + 1000:  # far outliers: sort rather than count
        return np.unique(idx, return_counts=True)
    counts = np.bincount(idx - lo)
    bins = np.flatnonzero(counts)
    return bins + lo, counts[bins]


def _merged(histograms: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Sparse histograms (bins, counts) summed into one."""
    if len(histograms) == 1:
        return histograms[0]
    bins, inverse = np.unique(np.concatenate([b for b, _ in histograms]), return_inverse=True)
    counts = np.bincount(inverse, weights=np.concatenate([c for _, c in histograms]))
    return bins, counts.astype(np.int64)


def _floor_bin(bins: np.ndarray, counts: np.ndarray) -> int:
    """The floor's bin of a sparse height histogram (bins sorted): its lowest strong peak."""
    left = _count_of(bins, counts, bins - 1)
    right = _count_of(bins, counts, bins + 1)
    strong = (counts >= PEAK_SHARE * counts.max()) & (counts >= left) & (counts >= right)
    return int(bins[np.argmax(strong)])  # lowest, as bins are sorted


def _count_of(bins: np.ndarray, counts: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Counts of the bins ``wanted`` in the sparse histogram (bins sorted), 0 where absent."""
    pos = np.clip(np.searchsorted(bins, wanted), 0, len(bins) - 1)
    return np.where(bins[pos] == wanted, counts[pos], 0)


def _finite_points(points: np.ndarray) -> np.ndarray:
    """(N, 3) float64 rows with finite coordinates (``points`` itself when it is that already);
    ValueError if the shape is wrong or none."""
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"expected (N, 3) points, got shape {pts.shape}")
    if not np.isfinite(pts).all():
        pts = pts[np.isfinite(pts).all(axis=1)]
    if len(pts) == 0:
        raise ValueError("no points")
    return pts
