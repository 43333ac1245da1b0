"""Tiny files written by other software (PDAL's, laspy's and pye57's test data, kept in
tests/data/real/ with their licences) read as their own libraries read them: every point of a
LAS/LAZ as laspy gives it, of an E57 as pye57 gives it (each scan placed by its pose), and a PCD
whose fields are named ``X Y Z`` with its values separated by spaces, tabs or commas."""

from __future__ import annotations

from pathlib import Path

import laspy
import numpy as np
import pye57
import pytest

from pcmapq.io import load_map

REAL = Path(__file__).resolve().parents[2] / "data" / "real"


@pytest.mark.parametrize(("name", "count"), [("pdal/simple.laz", 1065),
                                             ("laspy/1_4_w_evlr.laz", 1000),
                                             ("laspy/extra.laz", 1065)])
def test_las_and_laz_read_as_laspy_reads_them(name: str, count: int) -> None:
    las = laspy.read(REAL / name)
    got = load_map(REAL / name).points
    assert len(got) == count
    np.testing.assert_array_equal(got, np.column_stack([las.x, las.y, las.z]))


@pytest.mark.parametrize(("name", "count"), [("pdal/A_B.e57", 6),
                                             ("pye57/translationWithoutRotation.e57", 4),
                                             ("pye57/testWithNormals.e57", 2)])
def test_e57_reads_as_pye57_places_its_scans(name: str, count: int) -> None:
    e57 = pye57.E57(str(REAL / name))
    scans = [e57.read_scan(i, transform=True, ignore_missing_fields=True)
             for i in range(e57.scan_count)]
    want = np.vstack([np.column_stack([s[k] for k in ("cartesianX", "cartesianY",
                                                      "cartesianZ")]) for s in scans])
    got = load_map(REAL / name)
    assert len(got.points) == count
    if not got.is_3d:  # z constant: read as a 2D cloud, z = 0
        want[:, 2] = 0.0
    np.testing.assert_allclose(got.points, want, rtol=0, atol=1e-9)


def test_a_pose_without_rotation_moves_its_scan() -> None:
    """pye57's file: 4 points placed by a pose of translation only, at x 4..5 m, y 5..6 m."""
    points = load_map(REAL / "pye57" / "translationWithoutRotation.e57").points
    assert points[:, 0].min() == 4.0 and points[:, 1].min() == 5.0


@pytest.mark.parametrize("name", ["utm17_space.pcd", "utm17_tab.pcd", "utm17_comma.pcd"])
def test_pdal_s_ascii_pcd_reads_whatever_its_separator(name: str) -> None:
    """PDAL names the fields ``X Y Z``; its test files separate values by spaces, tabs or
    commas: each reads as the 10 points written, in metres."""
    lines = (REAL / "pdal" / "utm17_space.pcd").read_text().splitlines()[10:]
    want = np.array([[float(v) for v in line.split()] for line in lines])
    got = load_map(REAL / "pdal" / name)
    assert got.points.shape == (10, 3)
    np.testing.assert_array_equal(got.points, want)
    assert tuple(got.points[0]) == (289814.15, 4320978.61, 170.76)
