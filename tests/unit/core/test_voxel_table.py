"""Voxel centroids of a large cloud in one streamed pass: the same as the one-shot reduction,
bit for bit, whatever the chunks and the table's growth."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core import voxel_table
from pcmapq.core.errors import InputError
from pcmapq.core.voxels import STREAM_FROM, VoxelMap, voxel_centroids


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


def test_voxel_centroids_of_a_large_cloud_are_the_tables(monkeypatch):
    """A 3D cloud over STREAM_FROM points goes to the table, and gets the sort's centroids."""
    points = np.random.default_rng(2).normal(0, 5, (STREAM_FROM + 10, 3))
    calls = []
    table = voxel_table.streamed_centroids
    monkeypatch.setattr(voxel_table, "streamed_centroids",
                        lambda p, *rest: calls.append(len(p)) or table(p, *rest))
    one_shot = VoxelMap(0.2)
    one_shot.add(points)
    assert np.array_equal(voxel_centroids(points, 0.2), one_shot.points())
    voxel_centroids(points[:STREAM_FROM], 0.2)
    assert calls == [STREAM_FROM + 10]


def test_a_cloud_beyond_the_keys_range_is_refused_in_one_line():
    points = np.array([[0.0, 0.0, 0.0], [2e6, 0.0, 0.0]])
    with pytest.raises(InputError, match="beyond") as table:
        voxel_table.streamed_centroids(points, 0.1)
    one_shot_map = VoxelMap(0.1)
    one_shot_map.add(points)
    with pytest.raises(InputError) as one_shot:
        one_shot_map.points()
    assert str(table.value) == str(one_shot.value)
