"""3D rigid registration of the real LiDAR pair of ../shared/data/registration, with no initial
guess."""

from __future__ import annotations

import numpy as np
import open3d as o3d
import pytest

from pcmapq.align.rigid3d import align_3d
from testkit.paths import shared
from testkit.poses import apply, errors, rigid


def read_ply(path) -> np.ndarray:
    points = np.asarray(o3d.io.read_point_cloud(str(path)).points, dtype=np.float64)
    return points[(points != 0.0).any(axis=1)]  # no-return markers at exactly (0, 0, 0)


@pytest.fixture(scope="module")
def registration_pair() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    source = read_ply(shared("registration", "source.ply"))
    target = read_ply(shared("registration", "target.ply"))
    truth = np.loadtxt(shared("registration", "T_target_source.txt")).reshape(4, 4)
    assert len(target) == 69_088 - 5_032
    return source, target, truth


def test_recovers_the_registration_pair(registration_pair) -> None:
    source, target, truth = registration_pair
    result = align_3d(source, target, voxel=0.3)
    shift, angle = errors(result.transform, truth)
    assert shift < 0.05 and angle < 0.5
    assert result.fitness > 0.8 and 0.0 < result.rmse_m < 0.3


def test_recovers_the_registration_pair_turned_around(registration_pair) -> None:
    source, target, truth = registration_pair
    turn = rigid((0.0, 0.0, 150.0), (5.0, -3.0, 1.0))
    result = align_3d(apply(turn, source), target, voxel=0.3)
    shift, angle = errors(result.transform @ turn, truth)
    assert shift < 0.05 and angle < 0.5


def test_is_repeatable(registration_pair) -> None:
    source, target, _ = registration_pair
    first = align_3d(source, target, voxel=0.5)
    second = align_3d(source, target, voxel=0.5)
    assert np.array_equal(first.transform, second.transform)
    assert (first.fitness, first.rmse_m) == (second.fitness, second.rmse_m)
