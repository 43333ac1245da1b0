"""Exports for other tools (pcmapq.io.export): clouds and their fields read back by Open3D, the
matrix read back exactly."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.io.export import DISTANCE_FIELD, record_dtype, records, write_matrix, write_records
from pcmapq.report.export import colours
from testkit.files import read_cloud
from testkit.poses import rotation_about


@pytest.mark.parametrize("suffix", [".ply", ".pcd"])
def test_clouds_read_back_by_open3d(suffix, tmp_path):
    """Chunks of float32 points written as PLY or PCD: Open3D reads the same points."""
    rng = np.random.default_rng(0)
    xyz = rng.uniform(-50, 50, size=(1001, 3))
    dtype = record_dtype()
    write_records(tmp_path / f"c{suffix}", len(xyz),
                  (records(part, dtype) for part in np.array_split(xyz, 3)), dtype, "test")
    np.testing.assert_array_equal(read_cloud(tmp_path / f"c{suffix}")["positions"],
                                  xyz.astype(np.float32))


def test_distance_cloud_has_a_scalar_field_and_colours(tmp_path):
    xyz = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    distance = np.array([0.0, 0.25, 7.0])
    dtype = record_dtype(DISTANCE_FIELD, colour=True)
    write_records(tmp_path / "d.ply", 3, [records(xyz, dtype, distance,
                                                  colours(distance, 0.5))], dtype)
    back = read_cloud(tmp_path / "d.ply")
    np.testing.assert_array_equal(back[DISTANCE_FIELD].ravel(), distance.astype(np.float32))
    # viridis: dark blue at 0 m, yellow from the clip (0.5 m) on, a middle colour between
    assert back["colors"].tolist()[0] == [68, 1, 84] and back["colors"].tolist()[2][0] > 200
    assert len({tuple(c) for c in back["colors"].tolist()}) == 3


def test_a_cloud_with_colours_is_not_written_as_pcd(tmp_path):
    from pcmapq.core.errors import InputError

    dtype = record_dtype(DISTANCE_FIELD, colour=True)
    with pytest.raises(InputError, match="d.pcd: a cloud with colours"):
        write_records(tmp_path / "d.pcd", 0, [], dtype)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".ply", ".pcd", ".las"])
def test_a_scalar_field_is_read_back_by_pcmapq(suffix, tmp_path):
    """A cloud with a float scalar (a map's ``scan``) written as PLY, PCD or LAS: pcmapq reads
    its points back, and from PLY and PCD its scans."""
    from pcmapq.io import load_map

    xyz = np.random.default_rng(1).uniform(-5, 5, size=(50, 3))
    scan = np.repeat(np.arange(10) + 0.5, 5)
    dtype = record_dtype("scan")
    write_records(tmp_path / f"c{suffix}", 50, [records(xyz, dtype, scan)], dtype)
    back = load_map(tmp_path / f"c{suffix}")
    np.testing.assert_allclose(back.points, xyz, atol=1e-3 if suffix == ".las" else 1e-5)
    if suffix != ".las":
        np.testing.assert_array_equal(back.scan, scan.astype(np.float32))


def test_matrix_reads_back_exactly(tmp_path):
    m = np.eye(4)
    m[:3, :3] = rotation_about([0.3, 0.4, np.sqrt(0.75)], 33.3)
    m[:3, 3] = [1 / 3, -2e-7, 123.456]
    write_matrix(tmp_path / "T.txt", m)
    np.testing.assert_array_equal(np.loadtxt(tmp_path / "T.txt"), m)
    assert len((tmp_path / "T.txt").read_text().splitlines()) == 4
