"""small_gicp's point-to-plane ICP as pcmapq computes it (pcmapq.align.plane_icp): small_gicp's
transform and iterations, and each source point's nearest target point the KD-tree's own."""

from __future__ import annotations

import numpy as np
import pytest
import small_gicp

from pcmapq.align.plane_icp import Nearest, plane_icp, se3_exp
from testkit.poses import rigid


def scene(seed: int, bend_deg: float = 0.0) -> np.ndarray:
    """A street-like scene (ground, two facades, a box), 3 cm apart, 1 cm noise; with
    ``bend_deg``, each point turned about y by that much per 10 m along x (no rigid pose fits
    it, as a drifting map's)."""
    rng = np.random.default_rng(seed)
    n = 4000
    u, v = rng.uniform(size=(2, n))
    parts = [np.column_stack([40 * u, 12 * v - 6, 0 * u]),
             np.column_stack([40 * u, 0 * u + 6, 8 * v]),
             np.column_stack([25 * u, 0 * u - 6, 5 * v]),
             np.column_stack([10 + 3 * u, 1 + 0 * u, 2 * v]),
             np.column_stack([10 + 0 * u, 1 + 2 * u, 2 * v])]
    points = np.vstack(parts) + rng.normal(scale=0.01, size=(5 * n, 3))
    if bend_deg:
        angle = np.radians(bend_deg) * points[:, 0] / 10.0
        x, z = points[:, 0].copy(), points[:, 2].copy()
        points[:, 0] = x * np.cos(angle) + z * np.sin(angle)
        points[:, 2] = -x * np.sin(angle) + z * np.cos(angle)
    return points


def prepared(target: np.ndarray) -> tuple[small_gicp.PointCloud, small_gicp.KdTree]:
    cloud = small_gicp.PointCloud(target)
    tree = small_gicp.KdTree(cloud)
    small_gicp.estimate_normals(cloud, tree, num_neighbors=20)
    return cloud, tree


@pytest.mark.parametrize("bend_deg", [0.0, 0.5], ids=["rigid", "bent"])
def test_the_transform_and_iterations_are_small_gicps(bend_deg):
    source, target = scene(1, bend_deg), scene(0)
    guess = rigid((0.5, -0.4, 2.0), (0.3, -0.2, 0.1))
    cloud, tree = prepared(target)
    nearest = Nearest(source, np.ascontiguousarray(cloud.points()[:, :3]), tree)
    normals = np.ascontiguousarray(cloud.normals()[:, :3])
    ours = theirs = guess
    for distance in (1.0, 0.5, 0.25):  # stages on the same clouds share their neighbours
        fit = plane_icp(nearest, normals, ours, distance, 30, 1e-4, 1e-4)
        ours = fit.transform
        result = small_gicp.align(cloud, small_gicp.PointCloud(source), tree,
                                  init_T_target_source=theirs, registration_type="PLANE_ICP",
                                  max_correspondence_distance=distance, num_threads=1,
                                  max_iterations=30, rotation_epsilon=1e-4,
                                  translation_epsilon=1e-4)
        theirs = np.array(result.T_target_source)
        assert fit.steps == result.iterations
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
    assert nearest.searched < 3 * len(source)  # far fewer than a search per point and step


def test_the_nearest_target_points_are_the_kd_trees():
    """After moves of a few millimetres to a few centimetres, each point's kept neighbour is
    the one the KD-tree finds, on one thread or two."""
    source, target = scene(1), scene(0)
    cloud, tree = prepared(target)
    points = np.ascontiguousarray(cloud.points()[:, :3])
    kept = [Nearest(source, points, tree, threads=threads) for threads in (1, 2)]
    rng = np.random.default_rng(3)
    pose = np.eye(4)
    for _ in range(12):
        pose = pose @ se3_exp(np.concatenate([rng.normal(scale=1e-3, size=3),
                                              rng.normal(scale=0.01, size=3)]))
        rotation, shift = np.ascontiguousarray(pose[:3, :3]), pose[:3, 3].copy()
        found, _ = tree.batch_knn_search(source @ rotation.T + shift, 1)
        for nearest in kept:
            assert np.array_equal(nearest.at(rotation, shift), found[:, 0].astype(np.int64))
    assert kept[0].searched == kept[1].searched < 12 * len(source) / 2


def test_points_beyond_the_reach_are_not_searched_again():
    """Source points that no target point is near (a doubled floor 0.3 m above the target's,
    its nearest target points all about as far) are not searched again as the pose moves: within
    ``max_distance`` the pairs are still the KD-tree's, and beyond it the pair stays beyond it,
    so the fit counts the same pairs."""
    rng = np.random.default_rng(4)
    grid = np.stack(np.meshgrid(np.arange(0, 10, 0.05), np.arange(0, 10, 0.05)), -1)
    target = np.column_stack([grid.reshape(-1, 2), np.zeros(grid[..., 0].size)])
    source = rng.uniform([1, 1, 0], [9, 9, 0], size=(20000, 3))
    source[10000:, 2] = 0.3
    cloud, tree = prepared(target)
    points = np.ascontiguousarray(cloud.points()[:, :3])
    reach = 0.1
    kept, every = Nearest(source, points, tree), Nearest(source, points, tree)
    pose = np.eye(4)
    for _ in range(12):
        pose = pose @ se3_exp(np.concatenate([rng.normal(scale=1e-4, size=3),
                                              rng.normal(scale=2e-3, size=3)]))
        rotation, shift = np.ascontiguousarray(pose[:3, :3]), pose[:3, 3].copy()
        moved = source @ rotation.T + shift
        near = np.linalg.norm(points[every.at(rotation, shift)] - moved, axis=1) <= reach
        pair = kept.at(rotation, shift, reach)
        assert np.array_equal(pair[near], every.pair[near])
        assert (np.linalg.norm(points[pair[~near]] - moved[~near], axis=1) > reach).all()
    again, again_kept = every.searched - len(source), kept.searched - len(source)
    assert again > 3 * 10000  # the raised floor, searched at most steps without the reach
    assert again_kept < again / 20


def test_se3_exp_is_the_exponential_of_the_twist():
    from scipy.linalg import expm

    for delta in (np.array([0.1, -0.2, 0.3, 1.0, 2.0, -0.5]), np.array([1e-7, 0, 0, 0.1, 0, 0])):
        twist = np.zeros((4, 4))
        w = delta[:3]
        twist[:3, :3] = [[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]
        twist[:3, 3] = delta[3:]
        np.testing.assert_allclose(se3_exp(delta), expm(twist), atol=1e-12)
