"""Survey clouds: LAS and LAZ written by laspy and E57 by pye57 read back as their points (E57
scans placed by their poses), refused naming the file when broken, truncated or larger than
the memory allows."""

from __future__ import annotations

from pathlib import Path

import laspy
import numpy as np
import pye57
import pytest
from scipy.spatial.transform import Rotation

from pcmapq.core.errors import InputError
from pcmapq.io import load_map

POINTS = np.random.default_rng(0).uniform(-20.0, 20.0, (20_000, 3))


def write_las(path: Path, points: np.ndarray) -> Path:
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.scales = np.full(3, 0.0001)
    header.offsets = np.array([100.0, -50.0, 3.0])
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    las.write(path)
    return path


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_a_las_file_reads_as_its_points(suffix, tmp_path):
    got = load_map(write_las(tmp_path / f"cloud{suffix}", POINTS))
    assert got.is_3d and got.points.shape == POINTS.shape
    assert np.abs(got.points - POINTS).max() <= 0.00005 + 1e-9  # the 0.1 mm scale


def test_an_e57_file_reads_every_scan_placed_by_its_pose(tmp_path):
    path = tmp_path / "survey.e57"
    quarter = Rotation.from_euler("z", 90, degrees=True)
    e57 = pye57.E57(str(path), mode="w")
    first, second = POINTS[:10_000], POINTS[10_000:]
    e57.write_scan_raw({"cartesianX": first[:, 0], "cartesianY": first[:, 1],
                        "cartesianZ": first[:, 2]}, translation=np.array([1.0, 2.0, 3.0]),
                       rotation=np.array([1.0, 0.0, 0.0, 0.0]))
    x, y, z, w = quarter.as_quat()
    e57.write_scan_raw({"cartesianX": second[:, 0], "cartesianY": second[:, 1],
                        "cartesianZ": second[:, 2]}, translation=np.zeros(3),
                       rotation=np.array([w, x, y, z]))
    e57.close()
    got = load_map(path).points
    assert got.shape == POINTS.shape
    assert np.abs(got[:10_000] - (first + [1.0, 2.0, 3.0])).max() < 1e-5
    assert np.abs(got[10_000:] - quarter.apply(second)).max() < 1e-5


@pytest.mark.parametrize(("name", "data", "message"), [
    ("short.las", b"LASF" + bytes(50), "not a readable LAS/LAZ file"),
    ("empty.laz", b"", "not a readable LAS/LAZ file"),
    ("bad.e57", b"ASTM-E57" + bytes(60), "not a readable E57 file"),
])
def test_a_broken_survey_file_is_refused_naming_it(name, data, message, tmp_path):
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(InputError, match=f"{name}: {message}"):
        load_map(path)


def test_a_truncated_las_file_is_refused(tmp_path):
    path = write_las(tmp_path / "cloud.las", POINTS)
    path.write_bytes(path.read_bytes()[:-1000])
    with pytest.raises(InputError, match="cloud.las: "):
        load_map(path)


def test_a_las_file_declaring_too_many_points_is_refused_unread(tmp_path):
    path = write_las(tmp_path / "cloud.las", POINTS)
    with pytest.raises(InputError, match="20,000 points declared"):
        load_map(path, memory_limit=1000)
