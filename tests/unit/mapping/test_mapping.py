"""The LiDAR front end: scan folders, voxel accumulation, pose files, poses that move along their
z axis (KISS-ICP on KITTI 00: tests/realdata/test_kitti_mapping.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.core.voxels import voxel_keys
from pcmapq.mapping import (
    VoxelMap,
    build_map_from_poses,
    lidar_poses_from_camera,
    moves_along_z,
    open_scans,
    read_calib,
    read_kitti_poses,
    read_tum_poses,
    voxel_centroids,
    write_kitti_poses,
    write_tum_poses,
)
from testkit.kitti import TR_00, tr_00


def random_poses(count: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(count, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    x, y, z, w = q.T
    poses = np.tile(np.eye(4), (count, 1, 1))
    poses[:, :3, :3] = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)
    poses[:, :3, 3] = rng.uniform(-500, 500, size=(count, 3))
    return poses


# --- pose files ------------------------------------------------------------------------------

def test_kitti_round_trip_is_exact(tmp_path: Path) -> None:
    poses = random_poses(50)
    path = tmp_path / "poses.txt"
    write_kitti_poses(path, poses)
    again = read_kitti_poses(path)
    assert np.array_equal(again, poses)
    write_kitti_poses(tmp_path / "again.txt", again)
    assert (tmp_path / "again.txt").read_text() == path.read_text()
    assert all(len(line.split()) == 12 for line in path.read_text().splitlines())


def test_tum_round_trip(tmp_path: Path) -> None:
    poses = random_poses(50, seed=1)
    stamps = 1.6e9 + np.arange(50) * 0.1
    path = tmp_path / "traj.tum"
    write_tum_poses(path, poses, stamps)
    read_stamps, again = read_tum_poses(path)
    assert np.array_equal(read_stamps, stamps)
    assert np.array_equal(again[:, :3, 3], poses[:, :3, 3])
    assert np.array_equal(again[:, 3], poses[:, 3])
    assert np.abs(again[:, :3, :3] - poses[:, :3, :3]).max() < 1e-14
    rows = np.loadtxt(path)
    assert rows.shape == (50, 8) and np.all(rows[:, 7] >= 0)  # qw last, non-negative


def test_tum_default_timestamps_are_indices(tmp_path: Path) -> None:
    write_tum_poses(tmp_path / "t.txt", random_poses(3))
    stamps, _ = read_tum_poses(tmp_path / "t.txt")
    assert stamps.tolist() == [0.0, 1.0, 2.0]


def test_pose_files_skip_comments_and_reject_bad_lines(tmp_path: Path) -> None:
    good = tmp_path / "good.txt"
    good.write_text("# header\n\n1 0 0 0 0 1 0 0 0 0 1 5\n")
    assert read_kitti_poses(good)[0, 2, 3] == 5.0
    bad = tmp_path / "bad.txt"
    bad.write_text("1 0 0 0 0 1 0 0 0 0 1\n")
    with pytest.raises(InputError, match="line 1 has 11 numbers"):
        read_kitti_poses(bad)
    bad.write_text("0 1 2 3 0 0 0 0\n")
    with pytest.raises(InputError, match="zero quaternion"):
        read_tum_poses(bad)
    with pytest.raises(InputError, match="not found"):
        read_kitti_poses(tmp_path / "missing.txt")


def test_read_calib_forms(tmp_path: Path) -> None:
    plain = tmp_path / "tr.txt"
    plain.write_text(TR_00 + "\n")
    assert np.array_equal(read_calib(plain), tr_00())
    kitti = tmp_path / "calib.txt"
    kitti.write_text("P0: " + " ".join(["1"] * 12) + "\nP1: " + " ".join(["2"] * 12)
                     + "\nTr: " + TR_00 + "\n")
    assert np.array_equal(read_calib(kitti), tr_00())
    square = tmp_path / "t44.txt"
    square.write_text("1 0 0 1\n0 1 0 2\n0 0 1 3\n0 0 0 1\n")
    assert read_calib(square)[:3, 3].tolist() == [1.0, 2.0, 3.0]
    nokey = tmp_path / "nokey.txt"
    nokey.write_text("P0: " + " ".join(["1"] * 12) + "\n")
    with pytest.raises(InputError, match="no 'Tr:' line"):
        read_calib(nokey)
    short = tmp_path / "short.txt"
    short.write_text("1 2 3\n")
    with pytest.raises(InputError, match="3 numbers"):
        read_calib(short)


def test_lidar_poses_from_camera_conjugates() -> None:
    tr = tr_00()
    cam = random_poses(4, seed=2)
    lidar = lidar_poses_from_camera(cam, tr)
    point = np.array([3.0, -1.0, 0.5, 1.0])
    expected = (cam @ (tr @ point)) @ np.linalg.inv(tr).T  # row k: inv(Tr) @ P_k @ Tr @ point
    assert np.allclose(lidar @ point, expected)
    assert np.allclose(lidar_poses_from_camera(np.eye(4)[None], tr)[0], np.eye(4))


# --- scans and accumulation ------------------------------------------------------------------

def write_scans(folder: Path, scans: list[np.ndarray]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for index, scan in enumerate(scans):
        np.save(folder / f"{index}.npy", scan)
    return folder


def test_scan_folder_natural_order_and_velodyne_subfolder(tmp_path: Path) -> None:
    scans = [np.full((2, 3), float(i)) for i in range(12)]
    write_scans(tmp_path / "seq" / "velodyne", scans)
    sequence = open_scans(tmp_path / "seq")
    assert [f.name for f in sequence.files][:3] == ["0.npy", "1.npy", "2.npy"]
    assert [f.name for f in sequence.files][-1] == "11.npy"
    assert [float(points[0, 0]) for points, _ in sequence] == list(range(12))
    assert len(open_scans(tmp_path / "seq", max_scans=5)) == 5


def test_scan_sources_report_problems(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not found"):
        open_scans(tmp_path / "nothing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="no scan files"):
        open_scans(tmp_path / "empty")
    mixed = write_scans(tmp_path / "mixed", [np.zeros((2, 3))])
    (mixed / "1.bin").write_bytes(np.zeros(8, dtype="<f4").tobytes())
    with pytest.raises(InputError, match="several formats"):
        open_scans(mixed)


def test_build_map_from_poses_places_scans(tmp_path: Path) -> None:
    scan = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    folder = write_scans(tmp_path / "scans", [scan, scan])
    poses = np.tile(np.eye(4), (2, 1, 1))
    poses[1, :3, 3] = [10.0, 0.0, 0.0]
    calib = np.eye(4)
    calib[:3, 3] = [0.0, 0.0, 1.0]
    calls: list[tuple[int, int]] = []
    built = build_map_from_poses(folder, poses, calib, voxel=0.01,
                                 progress=lambda done, total: calls.append((done, total)))
    expected = np.array([[0, 2, 1], [1, 0, 1], [10, 2, 1], [11, 0, 1]], dtype=np.float64)
    assert np.allclose(built.points, expected)
    assert built.scan.tolist() == [0, 0, 1, 1]  # each point's scan
    assert calls == [(1, 2), (2, 2)]
    with pytest.raises(InputError, match="2 poses for 1 scan in"):
        build_map_from_poses(write_scans(tmp_path / "one", [scan]), poses)


def test_voxel_map_keeps_the_centroid_whatever_the_merges() -> None:
    rng = np.random.default_rng(3)
    points = rng.uniform(-5, 5, size=(20_000, 3))
    once = voxel_centroids(points, 0.5)
    grid = VoxelMap(0.5, min_flush=100)
    for chunk in np.array_split(points, 37):
        grid.add(chunk)
    assert np.allclose(grid.points(), once, atol=1e-12)
    cells = np.floor(points / 0.5)
    assert len(once) == len(np.unique(cells, axis=0))
    first = np.all(cells == cells[np.lexsort(cells.T[::-1])[0]], axis=1)
    assert np.allclose(once[0], points[first].mean(axis=0))


def test_voxel_keys_reject_far_points() -> None:
    with pytest.raises(InputError, match="larger voxel"):
        voxel_keys(np.array([[2e5, 0.0, 0.0]]), 0.1)


# --- KITTI 00: KISS-ICP map against the ground-truth map ----------------------------------


def test_moves_along_z():
    steps = np.tile(np.eye(4), (3, 1, 1))
    steps[:, :3, 3] = np.outer(np.arange(3), [0.1, 0.0, 0.9])
    assert moves_along_z(steps)
    steps[:, :3, 3] = np.outer(np.arange(3), [0.9, 0.1, 0.1])
    assert not moves_along_z(steps)
    steps[:, :3, 3] = np.outer(np.arange(3), [0.0, 0.0, 0.1])  # 0.2 m: too short to say
    assert not moves_along_z(steps)
