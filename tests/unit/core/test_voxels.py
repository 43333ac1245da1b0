"""Voxel centroids: grouping by counting on the points' box gives exactly what sorting gives."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from pcmapq.core import voxels
from pcmapq.core.bounds import bounds, nonzero_window
from pcmapq.core.voxels import (
    VoxelMap,
    evenly,
    voxel_centroids,
    voxel_count,
    voxel_groups,
    voxel_index,
    voxel_keys,
)


def by_sorting(points: np.ndarray, voxel: float) -> np.ndarray:
    """Centroids the plain way: unique keys, then sums and counts per key."""
    _, inverse = np.unique(voxel_keys(points, voxel), return_inverse=True)
    sums = np.column_stack([np.bincount(inverse, weights=points[:, axis])
                            for axis in range(points.shape[1])])
    return sums / np.bincount(inverse)[:, None]


@pytest.mark.parametrize("dims", [2, 3])
def test_counting_gives_the_sorted_centroids_bit_for_bit(dims: int) -> None:
    rng = np.random.default_rng(dims)
    # a bent wall: negative coordinates, many points a voxel
    t = rng.uniform(0, 1, 200_000)
    points = np.column_stack([-3 + 5 * t, 0.3 * np.sin(9 * t), rng.uniform(0, 2.6, len(t))])
    points = points[:, :dims] + rng.normal(0, 0.01, (len(t), dims))
    assert voxels._dense_groups(voxel_index(points, 0.05)) is not None  # counted
    np.testing.assert_array_equal(voxel_centroids(points, 0.05), by_sorting(points, 0.05))


def test_sparse_points_are_sorted() -> None:
    """Points far apart for their number: the box would be too large to count on."""
    points = np.array([[0.0, 0.0, 0.0], [500.0, 1.0, 2.0], [0.01, 0.02, 0.0], [-300, 4, 1]])
    assert voxels._dense_groups(voxel_index(points, 0.05)) is None
    np.testing.assert_array_equal(voxel_centroids(points, 0.05),
                                  [[-300, 4, 1], [0.005, 0.01, 0.0], [500, 1, 2]])


def test_voxel_map_counts_its_first_merge_and_sorts_the_next() -> None:
    rng = np.random.default_rng(0)
    first, second = rng.uniform(0, 3, (5000, 3)), rng.uniform(1, 4, (5000, 3))
    grid = VoxelMap(0.5, min_flush=100)
    grid.add(first)
    grid.add(second)
    np.testing.assert_allclose(grid.points(), by_sorting(np.vstack([first, second]), 0.5),
                               rtol=0, atol=1e-12)
    assert len(grid) == len(by_sorting(np.vstack([first, second]), 0.5))


@pytest.mark.parametrize("dims", [2, 3])
def test_voxel_count_is_the_number_of_centroids(dims: int) -> None:
    rng = np.random.default_rng(10 + dims)
    dense = rng.normal(0, 0.3, (50_000, dims))  # counted by voxel_centroids
    sparse = rng.uniform(-500, 500, (20_000, dims))  # sorted by voxel_centroids
    for points in (dense, sparse, np.vstack([sparse, sparse[:100]]), np.empty((0, dims))):
        assert voxel_count(points, 0.05) == len(voxel_centroids(points, 0.05))


def test_voxel_groups_are_numpys_unique_keys_and_inverse() -> None:
    rng = np.random.default_rng(7)
    dense = rng.normal(0, 0.3, (50_000, 3))  # counted
    sparse = rng.uniform(-500, 500, (2_000, 3))  # sorted
    assert voxels._dense_groups(voxel_index(dense, 0.05)) is not None
    assert voxels._dense_groups(voxel_index(sparse, 0.05)) is None
    for points in (dense, sparse):
        keys, inverse = voxel_groups(points, 0.05)
        want = np.unique(voxel_keys(points, 0.05), return_inverse=True)
        np.testing.assert_array_equal(keys, want[0])
        np.testing.assert_array_equal(inverse, want[1])


def test_evenly_spreads_over_the_order() -> None:
    points = np.arange(20.0).reshape(10, 2)
    np.testing.assert_array_equal(evenly(points, 4), points[[0, 3, 6, 9]])
    assert evenly(points, 10) is points and evenly(points, 50) is points


SHAPES = hnp.array_shapes(min_dims=2, max_dims=2, min_side=1, max_side=60).map(
    lambda s: (s[0], min(s[1], 3)))


@given(st.one_of(hnp.arrays(np.float64, SHAPES, elements=st.floats(allow_nan=True)),
                 hnp.arrays(np.int64, SHAPES)))
def test_bounds_are_numpys_over_axis_0(points):
    lo, hi = bounds(points)
    np.testing.assert_array_equal(lo, points.min(axis=0))
    np.testing.assert_array_equal(hi, points.max(axis=0))
    assert lo.dtype == hi.dtype == points.dtype


@given(hnp.arrays(bool, hnp.array_shapes(min_dims=2, max_dims=2, min_side=1, max_side=30)),
       st.integers(0, 5))
def test_nonzero_window_is_the_grown_box_of_nonzero_cells(image, margin):
    window = nonzero_window(image, margin)
    if not image.any():
        assert window is None
        return
    lo, hi, left, right = window
    rows, cols = np.nonzero(image)
    grown = np.zeros_like(image)
    grown[max(0, rows.min() - margin):rows.max() + 1 + margin,
          max(0, cols.min() - margin):cols.max() + 1 + margin] = True
    expected = np.zeros_like(image)
    expected[lo:hi, left:right] = True
    np.testing.assert_array_equal(expected, grown)


def test_a_carried_value_is_averaged_per_voxel_not_keyed() -> None:
    """Carried values (a scan's index) average over each voxel's points, whatever the merges;
    the voxels are those of the coordinates alone."""
    rng = np.random.default_rng(5)
    points = rng.uniform(0.0, 2.0, (3000, 3))
    scan = rng.integers(0, 9, 3000).astype(float)
    grid = VoxelMap(0.5, min_flush=700, carried=1)
    for part in np.array_split(np.column_stack([points, scan]), 5):
        grid.add(part)
    table = grid.points()
    np.testing.assert_allclose(table[:, :3], by_sorting(points, 0.5), atol=1e-12)
    _, inverse = np.unique(voxel_keys(points, 0.5), return_inverse=True)
    np.testing.assert_allclose(table[:, 3], np.bincount(inverse, scan) / np.bincount(inverse),
                               atol=1e-12)
