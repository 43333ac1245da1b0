"""The LiDAR front end on KITTI 00 (../shared/data/kitti00): its pose file round-trips, and
KISS-ICP's map and trajectory of the first scans against those of the reference poses."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.align.rigid3d import align_3d
from pcmapq.mapping import (
    build_map_from_poses,
    build_map_kiss,
    lidar_poses_from_camera,
    read_kitti_poses,
    write_kitti_poses,
)
from testkit.kitti import tr_00
from testkit.paths import shared


def test_kitti_file_of_sequence_00_round_trips(tmp_path: Path) -> None:
    path = shared("kitti00", "poses.txt")
    poses = read_kitti_poses(path)
    assert poses.shape == (20, 4, 4)
    table = np.loadtxt(path)
    assert np.array_equal(poses[:, :3, :].reshape(-1, 12), table)
    write_kitti_poses(tmp_path / "p.txt", poses)
    assert np.array_equal(read_kitti_poses(tmp_path / "p.txt"), poses)


@pytest.fixture(scope="module")
def kitti_maps() -> dict[str, np.ndarray]:
    kitti = shared("kitti00")
    shared("kitti00", "velodyne")
    camera_poses = read_kitti_poses(shared("kitti00", "poses.txt"))
    scans = 20
    calls: list[tuple[int, int]] = []
    kiss_map, kiss_poses = build_map_kiss(kitti, max_scans=scans, voxel=0.1,
                                          progress=lambda d, t: calls.append((d, t)))
    kiss_map = kiss_map.points
    truth_poses = lidar_poses_from_camera(camera_poses[:scans], tr_00())
    truth_map = build_map_from_poses(kitti, truth_poses, None, voxel=0.1).points
    return {"kiss_map": kiss_map, "kiss_poses": kiss_poses, "truth_map": truth_map,
            "truth_poses": truth_poses, "calls": np.array(calls)}


def test_kiss_map_matches_the_ground_truth_map(kitti_maps: dict[str, np.ndarray]) -> None:
    kiss_map, truth_map = kitti_maps["kiss_map"], kitti_maps["truth_map"]
    assert kiss_map.dtype == np.float64 and kiss_map.shape[1] == 3
    assert kitti_maps["kiss_poses"].shape == (20, 4, 4)
    assert np.allclose(kitti_maps["kiss_poses"][0], np.eye(4))
    assert kitti_maps["calls"].tolist() == [[k, 20] for k in range(1, 21)]
    result = align_3d(kiss_map, truth_map, voxel=0.5)
    assert result.fitness >= 0.9
    # Both maps are in the first LiDAR frame: the alignment stays small. It is not the
    # identity: KITTI's ground truth moves a constant 0.86 m per scan over these frames while
    # KISS-ICP sees the car accelerate (0.70 -> 0.89 m per scan), about 1 m apart by scan 10.
    assert np.linalg.norm(result.transform[:3, 3]) < 2.0
    angle = np.degrees(np.arccos(np.clip((np.trace(result.transform[:3, :3]) - 1) / 2, -1, 1)))
    assert angle < 3.0


def test_kiss_trajectory_against_ground_truth(kitti_maps: dict[str, np.ndarray]) -> None:
    kiss, truth = kitti_maps["kiss_poses"][:, :3, 3], kitti_maps["truth_poses"][:, :3, 3]
    kiss_steps = np.linalg.norm(np.diff(kiss, axis=0), axis=1)
    truth_steps = np.linalg.norm(np.diff(truth, axis=0), axis=1)
    assert np.ptp(truth_steps[:14]) < 0.01  # the ground truth is smooth: constant speed
    assert kiss_steps[-5:].mean() - kiss_steps[:5].mean() > 0.1  # KISS-ICP: accelerating
    assert abs(kiss_steps.sum() - truth_steps.sum()) < 0.1 * truth_steps.sum()
