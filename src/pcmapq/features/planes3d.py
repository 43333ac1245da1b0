"""The planes of a 3D cloud (walls, floors, ceilings, facades, ground): :func:`find_planes`.

Region growing on normals, vectorised: the cloud is reduced to one point per voxel (the
centroids of Open3D's ``voxel_down_sample``, streamed:
:func:`~pcmapq.core.voxels.open3d_centroids`), each point's normal and surface variation come
from the covariance of its nearest neighbours, and two neighbours join one region when both are
flat (low variation), their normals agree within :data:`NEIGHBOUR_ANGLE_DEG` and each lies
within half a voxel of the other's tangent plane: the regions are the connected components of
that graph (:mod:`pcmapq.core.components`, the pairs found ROWS points at a time, as is every
per-point step). A region's plane is fitted to its points (least squares), the points next to
it within half a voxel of that plane join it (the edges, where normals bend), and the plane is
fitted again. Each plane is kept with at least ``min_points`` points and ``min_area`` square
metres (the voxel-sized cells of the plane it covers). No random draw: the same cloud gives the
same planes. (Open3D's ``detect_planar_patches`` gives boxes without their points, and misses
faces of a metre or two; its planes could not be refitted nor measured.)

A plane is ``normal . x = offset``, its normal oriented with its largest component positive
(a floor's points up, a wall facing +x or +y); its extent is the bounding rectangle of its
points in the plane, along their principal axes. Metres, in the cloud's frame.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import small_gicp
from scipy import ndimage

from pcmapq.core.components import Components
from pcmapq.core.covariance import PAIRS, symmetric
from pcmapq.core.voxels import open3d_centroids
from pcmapq.features.local_shape import normals_and_variation

#: Nearest neighbours of a point's normal and of its edges in the region graph.
NEIGHBOURS = 12
#: A point is flat when its surface variation (the covariance's least eigenvalue over their
#: sum) is below this: 0 on a plane, 1/3 where points scatter alike in every direction.
MAX_VARIATION = 0.03
#: Two flat neighbours join one region when their normals agree within this, degrees.
NEIGHBOUR_ANGLE_DEG = 10.0
#: Rounds of growth: points next to a region and near its plane join it, once per round.
GROWTH_ROUNDS = 2
#: Threads that search the neighbours.
THREADS = os.cpu_count() or 1
#: Points whose per-point work (neighbours, normals, pairs, products) is done at once.
ROWS = 1 << 16


@dataclass(frozen=True)
class PlaneParams:
    """How planes are found. voxel: the cloud is reduced to one point per voxel of this side,
    metres (the scale of the planes found: a plane is at least a few voxels across);
    min_points: the fewest reduced points a plane keeps; min_area: its least area, square
    metres (the voxel-sized cells of the plane its points cover)."""

    voxel: float = 0.1
    min_points: int = 30
    min_area: float = 1.0


@dataclass(frozen=True)
class Planes:
    """P planes of one cloud, metres, in the cloud's frame.

    normal: (P, 3) unit normals, largest component positive. offset: (P,) so that
    ``normal . x = offset`` on the plane. centroid: (P, 3) the mean of its points.
    corners: (P, 4, 3) its bounding rectangle in the plane, corners in order (the first edge
    along its longer side). extent: (P, 2) the rectangle's sides, longer first. area: (P,)
    square metres its points cover. points: (P,) its points in the reduced cloud.
    """

    normal: np.ndarray
    offset: np.ndarray
    centroid: np.ndarray
    corners: np.ndarray
    extent: np.ndarray
    area: np.ndarray
    points: np.ndarray

    def __len__(self) -> int:
        return len(self.normal)

    @property
    def centre(self) -> np.ndarray:
        """(P, 3) the rectangles' centres."""
        return self.corners.mean(axis=1)

    @property
    def axes(self) -> np.ndarray:
        """(P, 2, 3) the rectangles' unit in-plane axes: along the first side, then the
        second."""
        sides = np.stack([self.corners[:, 1] - self.corners[:, 0],
                          self.corners[:, 3] - self.corners[:, 0]], axis=1)
        return sides / np.maximum(np.linalg.norm(sides, axis=2, keepdims=True), 1e-12)


def no_planes() -> Planes:
    """Planes with no plane in them."""
    return Planes(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 3)), np.zeros((0, 4, 3)),
                  np.zeros((0, 2)), np.zeros(0), np.zeros(0, dtype=np.int64))


def oriented(normal: np.ndarray) -> np.ndarray:
    """(N, 3) unit normals flipped so that each one's largest component is positive."""
    big = np.take_along_axis(normal, np.abs(normal).argmax(axis=1)[:, None], axis=1)
    return normal * np.where(big < 0, -1.0, 1.0)


def _rows(n: int) -> Iterator[slice]:
    """The rows 0 .. n - 1, ROWS at a time: the per-point work runs on one such block at a
    time, its temporaries (neighbours' coordinates, products, pairs) never for all points."""
    for start in range(0, n, ROWS):
        yield slice(start, min(start + ROWS, n))


def local_shape(points: np.ndarray, k: int = NEIGHBOURS
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each point's k nearest neighbours (N, k) indices (itself first; int32 below 2**31
    points), its unit normal (N, 3) and its surface variation (N,), from their covariance
    (:mod:`pcmapq.features.local_shape`).
    The neighbours are small_gicp's KD-tree's, on every core (SciPy's, in about half the
    time)."""
    n, k = len(points), min(k, len(points))
    points = np.ascontiguousarray(points, dtype=np.float64)
    tree = small_gicp.KdTree(points, num_threads=THREADS)
    near = np.empty((n, k), dtype=np.int32 if n < 2**31 else np.int64)
    normal, variation = np.empty((n, 3)), np.empty(n)
    for part in _rows(n):
        near[part] = tree.batch_knn_search(points[part], k, num_threads=THREADS)[0]
        normal[part], variation[part] = normals_and_variation(points, near[part])
    return near, normal, variation


def regions(points: np.ndarray, near: np.ndarray, normal: np.ndarray, flat: np.ndarray,
            voxel: float) -> np.ndarray:
    """(N,) each flat point's region (connected components of the graph of agreeing flat
    neighbours, numbered by their first point), -1 for a point that is not flat."""
    n, k = near.shape
    joined = Components(n)
    for part in _rows(n):
        i, j = np.repeat(np.arange(part.start, part.stop), k), near[part].ravel()
        keep = flat[i] & flat[j] & (i != j)
        i, j = i[keep], j[keep]
        agree = np.abs(np.einsum("ij,ij->i", normal[i], normal[j])) >= \
            np.cos(np.radians(NEIGHBOUR_ANGLE_DEG))
        close = np.abs(np.einsum("ij,ij->i", normal[i], points[j] - points[i])) <= voxel / 2
        keep = agree & close
        joined.join(i[keep], j[keep])
    return np.where(flat, joined.labels(), -1)


def fit(points: np.ndarray, label: np.ndarray, count: int
        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares planes of the labelled points (labels 0 .. count - 1; -1 none): their
    oriented normals (count, 3), offsets (count,) and centroids (count, 3)."""
    on = np.flatnonzero(label >= 0)
    lab = label[on]
    size = np.maximum(np.bincount(lab, minlength=count), 1)[:, None]
    centroid = np.stack([np.bincount(lab, weights=points[on, a], minlength=count)
                         for a in range(3)], axis=1) / size
    cov = _scatter(points, on, lab, centroid, count)
    normal = oriented(np.linalg.eigh(cov)[1][:, :, 0])
    return normal, np.einsum("ij,ij->i", normal, centroid), centroid


def _scatter(points: np.ndarray, on: np.ndarray, lab: np.ndarray, centroid: np.ndarray,
             count: int) -> np.ndarray:
    """(count, 3, 3) each plane's sum of the outer products of its points ``points[on]``
    (labels ``lab``) about its centroid, added in the points' order (each of the six distinct
    entries by one ``np.bincount``: with a plane's points in runs, ``np.add.at`` takes ten
    times as long for the same sums); the offsets from the centroids gathered ROWS at a time."""
    d = np.empty((len(on), 3))
    for part in _rows(len(on)):
        d[part] = points[on[part]] - centroid[lab[part]]
    return symmetric([np.bincount(lab, weights=d[:, a] * d[:, b], minlength=count)
                      for a, b in PAIRS])


def grow(points: np.ndarray, near: np.ndarray, label: np.ndarray, normal: np.ndarray,
         offset: np.ndarray, reach: float) -> np.ndarray:
    """The labels with each unlabelled point next to a labelled one, and within ``reach`` of
    its plane, given that neighbour's label (the nearest such plane's when several); each
    round's choices made on the labels the round starts with."""
    label = label.copy()
    for _ in range(GROWTH_ROUNDS):
        free = _next_to_plane(label, near)
        if not len(free):
            break
        taken = np.full(len(free), -1, dtype=label.dtype)
        for part in _rows(len(free)):
            rows = free[part]
            cand = label[near[rows]]  # (F, k) the neighbours' planes
            dist = np.abs(np.einsum("fkj,fj->fk", normal[np.maximum(cand, 0)], points[rows])
                          - offset[np.maximum(cand, 0)])
            dist = np.where((cand >= 0) & (dist <= reach), dist, np.inf)
            best = dist.argmin(axis=1)
            ok = np.isfinite(dist[np.arange(len(rows)), best])
            taken[part][ok] = cand[ok, best[ok]]
        label[free] = taken
    return label


def _next_to_plane(label: np.ndarray, near: np.ndarray) -> np.ndarray:
    """The points with no plane (``label`` -1) that have a neighbour (``near``) on one."""
    free = np.flatnonzero(label < 0)
    keep = np.empty(len(free), dtype=bool)
    for part in _rows(len(free)):
        keep[part] = (label[near[free[part]]] >= 0).any(axis=1)
    return free[keep]


def rectangles(points: np.ndarray, label: np.ndarray, normal: np.ndarray,
               centroid: np.ndarray, voxel: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each plane's bounding rectangle in the plane along its points' principal axes: corners
    (P, 4, 3) and sides (P, 2), the longer first; and the area its points cover (P,), square
    metres (:func:`covered`)."""
    count = len(normal)
    on = np.flatnonzero(label >= 0)
    lab = label[on]
    # the principal axes in the plane: the in-plane eigenvectors of each plane's covariance
    cov = _scatter(points, on, lab, centroid, count)
    axes = np.linalg.eigh(cov)[1][:, :, [2, 1]].transpose(0, 2, 1)  # (P, 2, 3): u, v
    axes = oriented(axes.reshape(-1, 3)).reshape(count, 2, 3)
    uv = np.empty((len(on), 2))
    for part in _rows(len(on)):
        d = points[on[part]] - centroid[lab[part]]
        uv[part] = np.einsum("nj,nkj->nk", d, axes[lab[part]])
    lo = np.stack([np.full(count, np.inf), np.full(count, np.inf)], axis=1)
    hi = -lo
    np.minimum.at(lo, lab, uv)
    np.maximum.at(hi, lab, uv)
    swap = (hi - lo)[:, 1] > (hi - lo)[:, 0]  # the longer side first
    axes[swap], lo[swap], hi[swap] = axes[swap][:, ::-1], lo[swap][:, ::-1], hi[swap][:, ::-1]
    corner_uv = np.stack([lo, np.stack([hi[:, 0], lo[:, 1]], 1), hi,
                          np.stack([lo[:, 0], hi[:, 1]], 1)], axis=1)  # (P, 4, 2)
    corners = centroid[:, None, :] + np.einsum("pck,pkj->pcj", corner_uv, axes)
    return corners, hi - lo, covered(lab, uv, count, voxel)


def covered(label: np.ndarray, uv: np.ndarray, count: int, voxel: float) -> np.ndarray:
    """(count,) the area each plane's points cover, square metres: the voxel-sized cells of
    the plane (``uv``, (N, 2) metres in its axes, of the points labelled 0 .. count - 1) that
    hold a point, with the holes of one cell closed (reduced points, about a voxel apart,
    leave some cells between them empty)."""
    cells = np.floor(uv / voxel).astype(np.int64)
    area = np.zeros(count)
    order = np.argsort(label, kind="stable")
    bounds = np.searchsorted(label[order], np.arange(count + 1))
    for k in range(count):  # one small raster per plane
        c = cells[order[bounds[k]:bounds[k + 1]]]
        if not len(c):
            continue
        c = c - c.min(axis=0) + 1
        raster = np.zeros(c.max(axis=0) + 2, dtype=bool)
        raster[c[:, 0], c[:, 1]] = True
        area[k] = np.count_nonzero(ndimage.binary_closing(raster, np.ones((3, 3), bool)))
    return area * voxel ** 2


def find_planes(points: np.ndarray, params: PlaneParams = PlaneParams()) -> Planes:
    """The planes of a cloud (N, 3) metres (see the module's docstring), largest first
    (ties by centroid), each with at least ``params.min_points`` reduced points and
    ``params.min_area`` square metres."""
    voxel = params.voxel
    pts = open3d_centroids(points, voxel)
    if len(pts) < max(params.min_points, 4):
        return no_planes()
    near, normal, variation = local_shape(pts)
    label = regions(pts, near, normal, variation < MAX_VARIATION, voxel)
    # the regions large enough to be a plane, numbered 0 .. count - 1
    sizes = np.bincount(label[label >= 0], minlength=1)
    big = np.flatnonzero(sizes >= max(params.min_points, 3))
    number = np.full(len(sizes) + 1, -1)
    number[big] = np.arange(len(big))
    label = number[label]  # -1 stays -1 (the last entry)
    count = len(big)
    if count == 0:
        return no_planes()
    plane_n, plane_d, _ = fit(pts, label, count)
    label = grow(pts, near, label, plane_n, plane_d, voxel / 2)
    plane_n, plane_d, centroid = fit(pts, label, count)
    corners, extent, area = rectangles(pts, label, plane_n, centroid, voxel)
    size = np.bincount(label[label >= 0], minlength=count)
    keep = (size >= params.min_points) & (area >= params.min_area)
    order = np.lexsort((centroid[:, 2], centroid[:, 1], centroid[:, 0], -size))
    order = order[keep[order]]
    return Planes(plane_n[order], plane_d[order], centroid[order], corners[order],
                  extent[order], area[order], size[order].astype(np.int64))
