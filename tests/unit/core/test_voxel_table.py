"""Voxel centroids of a large cloud in one streamed pass: the same as the one-shot reduction,
bit for bit, in 2D and 3D, whatever the chunks and the table's growth."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core import voxel_table
from pcmapq.core.errors import InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import STREAM_FROM, VoxelMap, voxel_centroids, voxel_count


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_streamed_centroids_equal_voxel_centroids_bit_for_bit(dtype, monkeypatch):
    rng = np.random.default_rng(1)
    points = np.vstack([rng.normal(0, 30, (40_000, 3)),  # mostly one point a voxel
                        rng.uniform(0, 0.5, (40_000, 3))]).astype(dtype)  # many a voxel
    monkeypatch.setattr(voxel_table, "CHUNK", 7_000)  # chunks and many doublings of the table
    got = voxel_table.streamed_centroids(points, 0.1, 2.5)
    one_shot = VoxelMap(0.1)  # voxel_centroids' sort, which it hands large clouds to the table
    one_shot.add(points.astype(np.float64) * 2.5)
    assert np.array_equal(got, one_shot.points())


@pytest.mark.parametrize("dense", [True, False])
def test_streamed_plan_points_equal_voxel_centroids_bit_for_bit(dense, monkeypatch):
    """2D points: the same as the one-shot reduction both ways it groups them (counting on a
    small box, sorting the keys of a large one)."""
    rng = np.random.default_rng(4)
    spread = 3.0 if dense else 3000.0
    points = np.vstack([rng.normal(0, spread, (40_000, 2)), rng.uniform(0, 0.5, (40_000, 2))])
    monkeypatch.setattr(voxel_table, "CHUNK", 7_000)
    got = voxel_table.streamed_centroids(points, 0.1)
    one_shot = VoxelMap(0.1, dims=2)
    one_shot.add(points)
    assert np.array_equal(got, one_shot.points())


def test_points_moved_chunk_by_chunk_give_the_centroids_of_the_moved_cloud(monkeypatch):
    """``move`` applied a chunk at a time (a map -> truth transform): the centroids of the
    whole cloud moved at once, bit for bit."""
    rng = np.random.default_rng(5)
    points = rng.normal(0, 20, (50_000, 2))
    move = Similarity2D(3.0, -7.0, np.radians(33.0), 1.0).apply
    monkeypatch.setattr(voxel_table, "CHUNK", 4_096)
    got = voxel_table.streamed_centroids(points, 0.15, move=move)
    assert np.array_equal(got, voxel_centroids(move(points), 0.15))


@pytest.mark.parametrize("dims", [2, 3])
def test_voxel_centroids_of_a_large_cloud_are_the_tables(dims, monkeypatch):
    """A cloud over STREAM_FROM points goes to the table, and gets the sort's centroids; its
    voxels are counted there too."""
    points = np.random.default_rng(2).normal(0, 5, (STREAM_FROM + 10, dims))
    calls = []
    table = voxel_table.streamed_centroids
    monkeypatch.setattr(voxel_table, "streamed_centroids",
                        lambda p, *rest, **kw: calls.append(len(p)) or table(p, *rest, **kw))
    one_shot = VoxelMap(0.2, dims=dims)
    one_shot.add(points)
    assert np.array_equal(voxel_centroids(points, 0.2), one_shot.points())
    voxel_centroids(points[:STREAM_FROM], 0.2)
    assert calls == [STREAM_FROM + 10]
    assert voxel_count(points, 0.2) == len(one_shot.points())
    assert voxel_count(points[:STREAM_FROM], 0.2) == len(voxel_centroids(points[:STREAM_FROM],
                                                                         0.2))
    assert calls == [STREAM_FROM + 10] * 2


@pytest.mark.parametrize("far", [[0.0, 0.0, 0.0, 2e6, 0.0, 0.0], [0.0, 0.0, 0.0, -2e9]])
def test_a_cloud_beyond_the_keys_range_is_refused_in_one_line(far):
    points = np.array(far).reshape(2, -1)
    with pytest.raises(InputError, match="beyond") as table:
        voxel_table.streamed_centroids(points, 0.1)
    one_shot_map = VoxelMap(0.1, dims=points.shape[1])
    one_shot_map.add(points)
    with pytest.raises(InputError) as one_shot:
        one_shot_map.points()
    assert str(table.value) == str(one_shot.value)


@pytest.mark.parametrize("dims", [2, 3])
@pytest.mark.parametrize("stripe_points", [9_000, 30_000, 79_999])
def test_a_cloud_reduced_in_stripes_of_x_gives_the_same_centroids(dims, stripe_points,
                                                                 monkeypatch):
    """Stripes of x, one pass each (moved chunk by chunk, on a float32 cloud, the table growing
    in each): the centroids of one pass, bit for bit and in their order."""
    rng = np.random.default_rng(6)
    points = np.vstack([rng.normal(0, 25, (40_000, dims)),
                        rng.uniform(0, 0.5, (40_000, dims))]).astype(np.float32)
    monkeypatch.setattr(voxel_table, "CHUNK", 7_000)
    whole = voxel_table.streamed_centroids(points, 0.1, 2.5)
    striped = voxel_table.streamed_centroids(points, 0.1, 2.5, stripe_points=stripe_points)
    assert np.array_equal(striped, whole)
    if dims == 2:
        move = Similarity2D(3.0, -7.0, np.radians(33.0), 1.0).apply
        assert np.array_equal(
            voxel_table.streamed_centroids(points, 0.15, move=move, stripe_points=stripe_points),
            voxel_table.streamed_centroids(points, 0.15, move=move))


def test_stripes_see_every_point_beyond_the_keys_range():
    """A point beyond the keys' range is refused whichever stripe it would fall in."""
    points = np.zeros((30_000, 3))
    points[-1, 1] = 1e9
    with pytest.raises(InputError, match="beyond"):
        voxel_table.streamed_centroids(points, 0.1, stripe_points=5_000)


@pytest.mark.parametrize("shift", [0.0, 6.0e5])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_open3d_centroids_are_open3ds_bit_for_bit(dtype, shift, monkeypatch):
    """Open3D's voxel_down_sample (its grid from half a voxel below the least corner), the
    same centroids bit for bit, read in small chunks and, past STRIPE_POINTS, in stripes; far
    from the origin too."""
    import open3d as o3d

    from pcmapq.core import voxels

    rng = np.random.default_rng(2)
    points = (np.vstack([rng.normal(0, 3, (30_000, 3)), rng.uniform(0, 0.5, (30_000, 3)),
                         np.round(rng.uniform(0, 2, (20_000, 3)), 1)])  # on voxel faces
              + shift).astype(dtype)
    down = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points.astype(np.float64)))
    expected = np.asarray(down.voxel_down_sample(0.1).points)
    expected = expected[np.lexsort(expected.T[::-1])]
    monkeypatch.setattr(voxel_table, "CHUNK", 7_000)
    assert np.array_equal(voxels.open3d_centroids(points, 0.1), expected)
    monkeypatch.setattr(voxels, "STRIPE_POINTS", 20_000)
    monkeypatch.setattr(voxels, "STRIPE_WIDTH_POINTS", 15_000)
    assert np.array_equal(voxels.open3d_centroids(points, 0.1), expected)
    assert voxels.open3d_centroids(points[:0], 0.1).shape == (0, 3)


def test_open3d_voxels_come_in_their_index_order_whatever_the_points_order():
    """Open3D's voxels (the same centroids as its voxel_down_sample), in the order of their
    index (x, then y, then z) rather than Open3D's, which follows the points' order: the
    same cloud with its points shuffled gives the same voxels in the same order."""
    from pcmapq.core import voxels

    rng = np.random.default_rng(4)
    points = rng.normal(0, 3, (40_000, 3))
    out = voxels.open3d_voxels(points, 0.1)
    assert np.array_equal(out[np.lexsort(out.T[::-1])], voxels.open3d_centroids(points, 0.1))
    index = np.floor((out - (points.min(axis=0) - 0.05)) / 0.1).astype(np.int64)
    step = np.diff(index, axis=0)  # each voxel after the last: the first axis that differs grows
    first = step[np.arange(len(step)), np.argmax(step != 0, axis=1)]
    assert np.all(first > 0)
    shuffled = voxels.open3d_voxels(points[rng.permutation(len(points))], 0.1)
    np.testing.assert_allclose(shuffled, out, rtol=0, atol=1e-12)
