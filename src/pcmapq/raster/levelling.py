"""The levelling of a 3D cloud: the smallest rotation that makes its dominant near-horizontal
plane (its floor, or a street's ground) horizontal, so that its wall band
(:mod:`pcmapq.raster.slice`) is cut level. Metres and degrees.
"""

from __future__ import annotations

import numba
import numpy as np

from pcmapq.core.voxels import open3d_voxels

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


def level_rotation(points: np.ndarray) -> np.ndarray:
    """The 3x3 rotation that makes the cloud's dominant near-horizontal plane horizontal;
    ``points`` (N, 3) metres, z roughly up, every coordinate finite.

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

    voxels = open3d_voxels(points, PLANE_VOXEL)
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


def _rotation_to_z(normal: np.ndarray) -> np.ndarray:
    """The smallest rotation (Rodrigues, about normal x z) taking unit ``normal`` to +z."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(normal, z)
    s, c = np.linalg.norm(axis), float(normal @ z)
    if s < 1e-12:
        return np.eye(3)
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + k + k @ k * ((1.0 - c) / s**2)
