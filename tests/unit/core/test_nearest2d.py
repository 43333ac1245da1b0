"""Nearest points in the plane within a distance, by buckets: SciPy's KD-tree's answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from pcmapq.core.nearest2d import BUCKETS_PER_POINT, NearestGrid


def _kd_tree(points: np.ndarray, query: np.ndarray, reach: float) -> np.ndarray:
    dist, j = cKDTree(points).query(query, distance_upper_bound=reach)
    return np.where(np.isfinite(dist), j, -1)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("reach", [0.01, 0.2, 1.0, 7.0])
def test_the_nearest_point_is_the_kd_trees(seed, reach):
    rng = np.random.default_rng(seed)
    # walls of dense points and a few strays, queried in and far outside their box
    t = rng.uniform(0, 10, 4000)
    walls = np.column_stack([t, np.round(t) % 3]) + rng.normal(0, 0.01, (4000, 2))
    points = np.vstack([walls, rng.uniform(-5, 15, (50, 2))])
    query = rng.uniform(-8, 18, (5000, 2))
    grid = NearestGrid(points, bucket=0.25)
    assert np.array_equal(grid.nearest(query, reach), _kd_tree(points, query, reach))


def test_a_point_at_exactly_the_distance_is_not_within_it():
    grid = NearestGrid(np.array([[0.0, 0.0], [1.0, 0.0]]))
    assert grid.nearest(np.array([[0.5, 0.0]]), 0.5).tolist() == [-1]
    assert grid.nearest(np.array([[0.5, 0.0]]), 0.6).tolist() == [0]  # a tie: the first


def test_points_spread_far_get_larger_buckets_and_the_same_answers():
    rng = np.random.default_rng(7)
    points = rng.uniform(0, 50_000, (1000, 2))
    grid = NearestGrid(points, bucket=0.25)
    assert grid.bucket > 0.25
    assert int(np.prod(grid.shape)) <= 1.1 * BUCKETS_PER_POINT * len(points)
    query = rng.uniform(0, 50_000, (2000, 2))
    assert np.array_equal(grid.nearest(query, 3000.0), _kd_tree(points, query, 3000.0))


def test_no_points_find_nothing():
    grid = NearestGrid(np.zeros((0, 2)))
    assert grid.nearest(np.array([[1.0, 2.0]]), 5.0).tolist() == [-1]
