"""The wall band of a 3D cloud: the points between two heights above the floor, seen from above.

Clouds are assumed roughly gravity aligned (z up, as LiDAR SLAM maps are); a small tilt is
removed first. All heights are metres.
"""

from __future__ import annotations

from collections.abc import Iterator

import numba
import numpy as np

from pcmapq.core.frames import Levelling
from pcmapq.core.voxels import open3d_voxels

#: Height histogram bin for finding the floor, metres.
FLOOR_BIN = 0.05
#: A histogram peak is "strong" when it holds at least this share of the largest bin's count.
PEAK_SHARE = 1.0 / 3.0
#: Planes whose normal is further than this from +z are not floors or ceilings, degrees.
MAX_TILT_DEG = 30.0
#: Voxel size of the copy searched for the floor plane, and plane inlier distance, metres.
PLANE_VOXEL = 0.1
PLANE_DISTANCE = 0.05
#: At most this many points (a seeded random subset of the voxel copy) go into RANSAC.
PLANE_POINTS = 20_000
#: How many planes (largest first) to try before giving up on levelling.
PLANE_TRIES = 3
#: The plane RANSAC finds is fitted again to every voxel within PLANE_DISTANCE of it until
#: those voxels stop changing, at most this many times.
REFITS = 50
#: Inliers whose second spread (singular value) is below this share of their first lie on a
#: line: no plane.
LINE_SHARE = 1e-6
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
    rotation = level_rotation(points[::step] if step > 1 else points)
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


def level_rotation(points: np.ndarray) -> np.ndarray:
    """The 3x3 rotation that makes the cloud's dominant near-horizontal plane horizontal.

    Open3D RANSAC (seeded, on a voxel-downsampled and randomly thinned copy: the voxels in their
    index order, so that the order of the cloud's points does not matter) finds the largest
    plane; planes whose normal is more than MAX_TILT_DEG from +z (walls) are set aside and the
    next largest tried, up to PLANE_TRIES. The accepted plane is fitted again by least squares
    to every voxel within PLANE_DISTANCE of it, until those voxels stop changing (at most
    REFITS times): RANSAC's plane, from a sample, can be a fraction of a degree off, and each
    fit takes in more of the true plane. The result is the smallest rotation taking its normal
    to +z (about the axis normal x z). The identity if no such plane is found.
    """
    import open3d as o3d  # heavy: loaded when a 3D map is levelled

    voxels = open3d_voxels(_finite_points(points), PLANE_VOXEL)
    sample = voxels
    if len(voxels) > PLANE_POINTS:
        sample = np.random.default_rng(0).choice(voxels, PLANE_POINTS, replace=False)
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(sample))
    for _ in range(PLANE_TRIES):
        if len(cloud.points) < 3:
            break
        o3d.utility.random.seed(0)
        model, inliers = cloud.segment_plane(PLANE_DISTANCE, 3, 1000)
        length = float(np.linalg.norm(model[:3]))
        if length == 0.0:  # points on one line: RANSAC returns a zero model, no plane
            break
        if abs(model[2]) / length >= np.cos(np.radians(MAX_TILT_DEG)):
            normal = _refitted(voxels, np.asarray(cloud.points)[inliers])
            return np.eye(3) if normal is None else _rotation_to_z(normal)
        cloud = cloud.select_by_index(inliers, invert=True)
    return np.eye(3)


def _refitted(voxels: np.ndarray, inliers: np.ndarray) -> np.ndarray | None:
    """The unit normal (pointing to +z) of the plane fitted to ``inliers`` (K, 3), then again
    to the ``voxels`` (N, 3) within PLANE_DISTANCE of the last fit until they stop changing (at
    most REFITS times); None when the points fitted lie on a line."""
    centre = inliers.mean(axis=0)
    centred = inliers - centre
    fit = _plane(centred.T @ centred, centre)
    near = np.zeros(len(voxels), dtype=np.bool_)
    for _ in range(REFITS):
        if fit is None:
            return None
        changed, count, centre, scatter = _near_moments(voxels, *fit, PLANE_DISTANCE, near)
        if not changed:
            break
        fit = _plane(scatter, centre) if count >= 3 else None
    return None if fit is None else fit[0]


def _plane(scatter: np.ndarray, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The least-squares plane of points whose scatter matrix (3, 3; the sum of their centred
    outer products) and centroid (3,) are given: its unit normal (pointing to +z) and the
    centroid; None when they lie on a line."""
    values, vectors = np.linalg.eigh(scatter)  # ascending
    if values[1] <= LINE_SHARE**2 * values[2]:
        return None
    normal = vectors[:, 0]
    return (normal if normal[2] >= 0 else -normal), centre


@numba.njit(cache=True, nogil=True)
def _near_moments(points: np.ndarray, normal: np.ndarray, centre: np.ndarray, reach: float,
                  near: np.ndarray) -> tuple[bool, int, np.ndarray, np.ndarray]:
    """Mark in ``near`` (N,) the points (N, 3) within ``reach`` metres of the plane through
    ``centre`` with unit ``normal``; whether any mark changed, how many are marked, their
    centroid and their scatter matrix (the sum of their centred outer products), summed about
    ``centre`` for precision."""
    changed = False
    count = 0
    first = np.zeros(3)
    second = np.zeros((3, 3))
    for i in range(points.shape[0]):
        d0 = points[i, 0] - centre[0]
        d1 = points[i, 1] - centre[1]
        d2 = points[i, 2] - centre[2]
        inside = abs(d0 * normal[0] + d1 * normal[1] + d2 * normal[2]) <= reach
        if inside != near[i]:
            near[i] = inside
            changed = True
        if inside:
            count += 1
            d = (d0, d1, d2)
            for a in range(3):
                first[a] += d[a]
                for b in range(a, 3):
                    second[a, b] += d[a] * d[b]
    mean = first / max(count, 1)
    for a in range(3):
        for b in range(a, 3):
            second[a, b] -= count * mean[a] * mean[b]
            second[b, a] = second[a, b]
    return changed, count, centre + mean, second


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


def _rotation_to_z(normal: np.ndarray) -> np.ndarray:
    """The smallest rotation (Rodrigues, about normal x z) taking unit ``normal`` to +z."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(normal, z)
    s, c = np.linalg.norm(axis), float(normal @ z)
    if s < 1e-12:
        return np.eye(3)
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + k + k @ k * ((1.0 - c) / s**2)


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
