"""Voxel centroids: a global point map accumulated scan by scan, one point per voxel, memory
bounded; and the one-shot downsampling of a cloud (2D or 3D) to one point per voxel.

Points are buffered and merged into the map whenever the buffer holds as many points as the map
(at least ``min_flush`` points): the merge keys each point by its voxel, and each voxel keeps the
centroid of **every** point that ever fell in it (running sums and counts), so the result does
not depend on when merges happen. Memory stays within about twice the final map plus one scan;
the total merge cost is O(n log n) over the sequence. Deterministic: voxels come out sorted by
their integer index (x, then y, then z).

Points merged into an empty map whose bounding box holds few voxels for their number (a plan's
walls at 0.05 m, a downsampled cloud) are grouped by counting on that box instead of sorting:
the same voxels, the same order and the same sums (every voxel adds its points in their order),
in linear time.
"""

from __future__ import annotations

import numpy as np

from pcmapq.core import voxel_table
from pcmapq.core.bounds import bounds
from pcmapq.core.errors import InputError

__all__ = ["VoxelMap", "evenly", "index_keys", "open3d_centroids", "open3d_voxels",
           "stripe_points", "voxel_centroids", "voxel_count", "voxel_groups"]

#: Grouping by counting is used when the points' box holds at most this many voxels per point
#: and at most DENSE_CELLS voxels (8 bytes of memory each).
DENSE_PER_POINT = 4
DENSE_CELLS = 1 << 27
#: Clouds (2D or 3D) of more points than this are grouped by the compiled hash table
#: (:mod:`pcmapq.core.voxel_table`): the same centroids in the same order, in memory that grows
#: with the voxels rather than the points, and with only the voxels sorted. Smaller ones are
#: sorted, which spares a short run loading the table.
STREAM_FROM = 100_000
#: Voxels from the grid's corner that the compiled table's keys reach along an axis (3D: 2**20
#: less one): :func:`open3d_centroids` leaves a wider cloud to Open3D.
REACH = (1 << 20) - 1
#: A cloud of more points than this is reduced in stripes of x (:func:`stripe_points`), one
#: pass over its points each, so that the voxel table holds one stripe's voxels at a time, not
#: a large cloud's whole table beside the evaluation (docs/benchmarks.md).
STRIPE_POINTS = 25_000_000
#: Such a cloud's stripes hold about this many points each: the table of one stripe's voxels and
#: the centroids of the stripes before it stand beside the plan's global search, whose peak the
#: stripes' width barely moves.
STRIPE_WIDTH_POINTS = 8_000_000


class VoxelMap:
    """Voxel-hash accumulator of world-frame points (metres).

    voxel: cell edge, metres. min_flush: buffered points that always trigger a merge.
    dims: coordinates per point (3; 2 for planar points). carried: values per point after its
    coordinates that each voxel averages too without being keyed by them (a scan's index).
    """

    def __init__(self, voxel: float, min_flush: int = 1_000_000, dims: int = 3,
                 carried: int = 0) -> None:
        if not voxel > 0:
            raise InputError(f"voxel must be positive, got {voxel}")
        self.voxel = float(voxel)
        self.min_flush = int(min_flush)
        self.dims = int(dims)
        self._keys = np.empty(0, dtype=np.int64)
        self._sums = np.empty((0, dims + carried), dtype=np.float64)
        self._counts = np.empty(0, dtype=np.int64)
        self._buffer: list[np.ndarray] = []
        self._buffered = 0

    def __len__(self) -> int:
        """Voxels in the map (buffered points merged first)."""
        self._merge()
        return len(self._keys)

    def add(self, points: np.ndarray) -> None:
        """Add world-frame points (N, dims + carried), metres then the carried values; merges
        when the buffer is large enough."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, self._sums.shape[1])
        if len(points) == 0:
            return
        self._buffer.append(points)
        self._buffered += len(points)
        if self._buffered >= max(self.min_flush, len(self._keys)):
            self._merge()

    def points(self) -> np.ndarray:
        """The map: (M, dims + carried) float64 voxel centroids, metres (then each voxel's mean
        carried values), sorted by voxel index."""
        self._merge()
        return self._sums / self._counts[:, None]

    def _merge(self) -> None:
        if not self._buffer:
            return
        new = np.concatenate(self._buffer)
        self._buffer, self._buffered = [], 0
        index = voxel_index(new[:, :self.dims], self.voxel)
        dense = _dense_groups(index) if len(self._keys) == 0 else None
        if dense is not None:
            self._keys, inverse = dense
            self._counts = np.bincount(inverse).astype(np.int64)
            self._sums = np.column_stack([np.bincount(inverse, weights=new[:, axis])
                                          for axis in range(new.shape[1])])
            return
        keys = np.concatenate([self._keys, _packed(index)])
        sums = np.concatenate([self._sums, new])
        counts = np.concatenate([self._counts, np.ones(len(new), dtype=np.int64)])
        self._keys, inverse = np.unique(keys, return_inverse=True)
        self._counts = np.bincount(inverse, weights=counts).astype(np.int64)
        self._sums = np.column_stack([np.bincount(inverse, weights=sums[:, axis])
                                      for axis in range(new.shape[1])])


def voxel_keys(points: np.ndarray, voxel: float) -> np.ndarray:
    """One int64 key per point (N, d, metres), d <= 3: its voxel index packed in 63 // d bits an
    axis (21 in 3D: +-104 km at 0.1 m; 31 in 2D), so keys sort as the indices (x, then y, ...).

    Raises InputError when a point lies beyond +-2**(bits - 1) voxels of the origin.
    """
    return _packed(voxel_index(points, voxel))


def voxel_groups(points: np.ndarray, voxel: float) -> tuple[np.ndarray, np.ndarray]:
    """The occupied voxels' packed keys (sorted, :func:`voxel_keys`) and each point's (N, d,
    metres) place among them, as ``np.unique(voxel_keys(points, voxel), return_inverse=True)``
    gives them: by counting on the voxels' bounding box when it is small for the points
    (linear time), else by sorting."""
    index = voxel_index(np.asarray(points, dtype=np.float64), voxel)
    dense = _dense_groups(index)
    return np.unique(_packed(index), return_inverse=True) if dense is None else dense


def voxel_index(points: np.ndarray, voxel: float) -> np.ndarray:
    """Each point's (N, d, metres) voxel index (N, d) int64, shifted by 2**(bits - 1) so that it
    is in [0, 2**bits) (see :func:`voxel_keys`); InputError beyond."""
    bits = 63 // points.shape[1]
    offset = 1 << (bits - 1)
    index = np.floor(points / voxel).astype(np.int64) + offset
    if len(index) and (index.min() < 0 or index.max() >= (1 << bits)):
        raise InputError(f"map extends beyond +-{offset * voxel:.0f} m of its origin at voxel "
                         f"{voxel} m; use a larger voxel")
    return index


def index_keys(index: np.ndarray) -> np.ndarray:
    """:func:`voxel_index` rows (N, d) packed into their keys (:func:`voxel_keys`)."""
    return _packed(np.asarray(index, dtype=np.int64))


def _packed(index: np.ndarray) -> np.ndarray:
    """:func:`voxel_index` (N, d) packed into one int64 key per point."""
    bits = 63 // index.shape[1]
    keys = index[:, 0]
    for axis in range(1, index.shape[1]):
        keys = (keys << bits) | index[:, axis]
    return keys


def _dense_groups(index: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The sorted unique keys of voxel indices (N, d) and each point's position among them,
    as ``np.unique(_packed(index), return_inverse=True)`` gives them, found by counting on the
    indices' bounding box; None when that box is too large (DENSE_PER_POINT, DENSE_CELLS)."""
    if len(index) == 0:
        return None
    lo, hi = bounds(index)
    span = hi - lo + 1
    cells = int(np.prod(span.astype(object)))
    if cells > min(DENSE_PER_POINT * len(index) + 4096, DENSE_CELLS):
        return None
    linear = index[:, 0] - lo[0]  # row-major in the box: sorts as the packed keys
    for axis in range(1, index.shape[1]):
        linear = linear * span[axis] + (index[:, axis] - lo[axis])
    slots = np.bincount(linear, minlength=cells)  # points per cell, then each cell's rank
    occupied = np.flatnonzero(slots)
    slots[occupied] = np.arange(len(occupied))
    keys = _packed(np.column_stack(np.unravel_index(occupied, tuple(span))) + lo)
    return keys, slots[linear]


def voxel_centroids(points: np.ndarray, voxel: float, scale: float = 1.0,
                    stripe_points: int | None = None) -> np.ndarray:
    """The centroid of the points (N, d; d = 2 or 3) times ``scale``, metres, in each
    ``voxel``-metre cell, (M, d), sorted by voxel index (x, then y, ...). Deterministic. A large
    cloud (a file mapped into memory, say) is read in chunks, never converted whole; with more
    than ``stripe_points`` points, in stripes of x, a pass each, holding one stripe's voxels at
    a time (:func:`~pcmapq.core.voxel_table.streamed_centroids`)."""
    points = np.asarray(points)
    if points.ndim == 2 and points.shape[1] in (2, 3) and len(points) > STREAM_FROM:
        return voxel_table.streamed_centroids(points, voxel, scale,  # the same, without a sort
                                              stripe_points=stripe_points)
    points = np.asarray(points, dtype=np.float64)
    if scale != 1.0:
        points = points * scale
    grid = VoxelMap(voxel, dims=points.shape[1])
    grid.add(points)
    return grid.points()


def stripe_points(points: int) -> int | None:
    """The ``stripe_points`` of a reduction of ``points`` points: None (one pass) up to
    STRIPE_POINTS, else stripes of about STRIPE_WIDTH_POINTS points."""
    return None if points <= STRIPE_POINTS else STRIPE_WIDTH_POINTS


def open3d_centroids(points: np.ndarray, voxel: float) -> np.ndarray:
    """The centroids (M, 3) of :func:`open3d_voxels`, in lexicographic order (x, then y, then
    z)."""
    out = open3d_voxels(points, voxel)
    return out[np.lexsort(out.T[::-1])]


def open3d_voxels(points: np.ndarray, voxel: float) -> np.ndarray:
    """The centroids (M, 3) of the points (N, 3, metres, any float type) in each voxel of
    Open3D's ``voxel_down_sample``, bit for bit (its cubes start half a voxel below the
    cloud's least corner; each voxel's points are summed in their order), in the voxels' index
    order (x, then y, then z), not Open3D's, which follows the order of the input. Read in
    chunks by the compiled table (a file mapped into memory is never converted whole; more
    than STRIPE_POINTS points in stripes of x); Open3D itself reduces a cloud wider than the
    table's keys reach (a float64 copy of it), its centroids then in lexicographic order."""
    points = np.asarray(points)
    if len(points) == 0:
        return np.zeros((0, 3))
    lo, hi = (b.astype(np.float64) for b in bounds(points))
    corner = lo - voxel * 0.5
    if float(np.max((hi - corner) / voxel)) < REACH:
        return voxel_table.streamed_centroids(points, voxel, origin=corner,
                                              stripe_points=stripe_points(len(points)))
    import open3d as o3d  # only here: Open3D loads in seconds

    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(
        np.asarray(points, dtype=np.float64)))
    out = np.asarray(cloud.voxel_down_sample(voxel).points)
    return out[np.lexsort(out.T[::-1])]


def voxel_count(points: np.ndarray, voxel: float) -> int:
    """How many ``voxel``-metre cells hold at least one of the points (N, d, metres): the length
    of :func:`voxel_centroids`; for a few points found by sorting the voxel keys alone."""
    points = np.asarray(points)
    if points.ndim == 2 and points.shape[1] in (2, 3) and len(points) > STREAM_FROM:
        return len(voxel_table.streamed_centroids(points, voxel))
    keys = np.sort(voxel_keys(np.asarray(points, dtype=np.float64), voxel))
    return int(len(keys) > 0) + int(np.count_nonzero(keys[1:] != keys[:-1]))


def evenly(points: np.ndarray, count: int) -> np.ndarray:
    """At most ``count`` of the points (N, d), evenly spaced in their order (from
    :func:`voxel_centroids`, voxel order: a spread over the whole cloud), the first and last
    kept; all of them when there are no more."""
    if len(points) <= count:
        return points
    return points[np.linspace(0, len(points) - 1, count).astype(np.int64)]


def thinned(xy: np.ndarray, voxel: float, max_points: int) -> tuple[np.ndarray, float]:
    """Voxel centroids of ``xy`` (N, 2, metres) at ``voxel`` metres; when more than
    ``max_points``, at the voxel grown by the ratio (about ``max_points`` remain on walls).
    Returns them and the voxel used, metres. Beyond ``max_points`` points the voxels are counted
    first: a few points by sorting their keys, so a cloud to be thinned is grouped once, at the
    grown voxel; more than STREAM_FROM by the compiled table, which counts them by grouping
    them, so that grouping is kept when it is the answer."""
    if len(xy) > max_points:
        fine = voxel_centroids(xy, voxel) if len(xy) > STREAM_FROM else None
        count = voxel_count(xy, voxel) if fine is None else len(fine)
        if count > max_points:
            grown = voxel * count / max_points
            return voxel_centroids(xy, grown), grown
        if fine is not None:
            return fine, voxel
    return voxel_centroids(xy, voxel), voxel
