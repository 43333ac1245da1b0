"""CARMEN laser logs: FLASER parsing, endpoints in the world frame, no-return codes, errors."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io import PointMap, load_map
from pcmapq.io.carmen import beam_angles, endpoints, load_carmen, read_flaser

#: Other message types a log holds, which the reader must skip.
HEADER = ("# message formats defined: PARAM SYNC ODOM FLASER RLASER\n"
          "PARAM robot_frontlaser_offset 0.0 nohost 0\n"
          "ODOM 0.0 0.0 0.0 0 0 0 1.0 nohost 1.0\n")


def flaser(ranges: list[float], pose: tuple[float, float, float]) -> str:
    """One FLASER line: the ranges (metres) seen from the laser pose (x, y metres, theta rad)."""
    x, y, theta = pose
    values = " ".join(f"{r:g}" for r in ranges)
    return (f"FLASER {len(ranges)} {values} {x!r} {y!r} {theta!r} {x!r} {y!r} {theta!r} "
            "12.5 pippo 12.5\n")


def write_log(path: Path, body: str) -> Path:
    """Write a log plain, or gzip-compressed when the name ends with .gz."""
    text = HEADER + body + "NEFF 1 2 3\n"
    if path.suffix == ".gz":
        path.write_bytes(gzip.compress(text.encode()))
    else:
        path.write_text(text)
    return path


#: Three beams: -90, 0 and +90 degrees; seen from (1, 2) facing +y they end at (2, 2), (1, 4)
#: and (-2, 2).
THREE = flaser([1.0, 2.0, 3.0], (1.0, 2.0, np.pi / 2))
THREE_XY = [[2.0, 2.0], [1.0, 4.0], [-2.0, 2.0]]


@pytest.mark.parametrize("name", ["run.log", "run.log.gz", "RUN.LOG.GZ"])
def test_endpoints_in_world_frame_plain_and_gzip(tmp_path: Path, name: str) -> None:
    path = write_log(tmp_path / name, THREE + flaser([0.5, 1.5, 4.0], (0.0, 0.0, 0.0)))
    cloud = load_map(path)
    assert isinstance(cloud, PointMap) and not cloud.is_3d and cloud.kind == "carmen"
    assert cloud.points.shape == (6, 3) and (cloud.points[:, 2] == 0).all()
    np.testing.assert_allclose(cloud.points[:, :2],
                               THREE_XY + [[0.0, -0.5], [1.5, 0.0], [0.0, 4.0]], atol=1e-12)


def test_sick_beam_angles() -> None:
    """CARMEN's convention: from -90 degrees in steps of 1 (180, 181 beams) or 0.5 (360, 361)."""
    for n, step in [(180, 1.0), (181, 1.0), (360, 0.5), (361, 0.5), (3, 90.0)]:
        degrees = np.degrees(beam_angles(n))
        assert degrees[0] == pytest.approx(-90.0) and len(degrees) == n
        np.testing.assert_allclose(np.diff(degrees), step)


def test_181_beam_scan(tmp_path: Path) -> None:
    ranges = [2.0 + 0.01 * i for i in range(181)]
    path = write_log(tmp_path / "sick.log", flaser(ranges, (3.0, -1.0, np.pi)))
    xy = load_carmen(path).points[:, :2]
    # beam i points at 180 - 90 + i degrees in the world: beam 45 (2.45 m) at 135 degrees
    np.testing.assert_allclose(xy[45], [3.0 - 2.45 * np.sqrt(0.5), -1.0 + 2.45 * np.sqrt(0.5)],
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(xy - [3.0, -1.0], axis=1), ranges, atol=1e-12)


def test_no_return_and_long_readings_dropped(tmp_path: Path) -> None:
    """81.91 m, seen in many beams, is the no-return code whatever max_range; 35 m is a real
    reading, kept only when max_range allows it."""
    body = flaser([1.0, 81.91, 35.0, 81.91], (0.0, 0.0, 0.0)) * 5
    path = write_log(tmp_path / "max.log", body)
    assert len(load_carmen(path).points) == 5  # the 1 m beam of each scan
    assert len(load_carmen(path, max_range=100.0).points) == 10  # and the 35 m one
    poses, ranges, angles = read_flaser(path)
    assert poses.shape == (5, 3) and ranges.shape == angles.shape == (5, 4)
    assert np.isnan(ranges[:, [1, 3]]).all() and (ranges[:, 2] == 35.0).all()


def test_varying_beam_counts(tmp_path: Path) -> None:
    path = write_log(tmp_path / "mixed.log", THREE + flaser([1.0] * 5, (0.0, 0.0, 0.0)) + THREE)
    poses, ranges, angles = read_flaser(path)
    assert ranges.shape == (3, 5)
    assert np.isnan(ranges[[0, 2], 3:]).all() and not np.isnan(ranges[1]).any()
    xy = endpoints(poses, ranges, angles, 30.0)
    np.testing.assert_allclose(xy[:3], THREE_XY, atol=1e-12)
    np.testing.assert_allclose(xy[8:], THREE_XY, atol=1e-12)
    np.testing.assert_allclose(xy[3:8], [[0, -1], [np.sqrt(0.5), -np.sqrt(0.5)], [1, 0],
                                         [np.sqrt(0.5), np.sqrt(0.5)], [0, 1]], atol=1e-12)


def test_endpoints_along_other_poses() -> None:
    """The tool's use: the same scans placed along other poses."""
    ranges = np.array([[1.0, np.nan, 3.0]])
    xy = endpoints(np.array([[5.0, 5.0, 0.0]]), ranges, beam_angles(3), max_range=30.0)
    np.testing.assert_allclose(xy, [[5.0, 4.0], [5.0, 8.0]], atol=1e-12)


@pytest.mark.parametrize(("body", "problem"), [
    ("", "no FLASER line"),
    (flaser([1.0, 2.0, 3.0], (0, 0, 0)).replace(" 2 ", " two "),
     "line 4: FLASER range 2 'two' is not a number"),
    ("FLASER 3 1 2 3 0 0 0 0 0 0 12.5 pippo\n", "line 4: FLASER with 3 beams needs 14 fields"),
    ("FLASER x 1 2 3 0 0 0 0 0 0 12.5 pippo 12.5\n", "line 4: FLASER beam count 'x'"),
    (THREE + flaser([1.0, 2.0, 3.0], (0, float("nan"), 0)), "pose is not a finite number"),
    (flaser([40.0, 50.0], (0, 0, 0)), "no laser reading within 30 m"),
])
def test_bad_logs(tmp_path: Path, body: str, problem: str) -> None:
    path = write_log(tmp_path / "bad.log", body)
    with pytest.raises(InputError) as info:
        load_map(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and problem in message and "\n" not in message


def test_corrupt_gzip(tmp_path: Path) -> None:
    path = tmp_path / "broken.log.gz"
    path.write_bytes(gzip.compress(b"FLASER 1 1 0 0 0 0 0 0 1 h 1\n")[:-12])
    with pytest.raises(InputError, match=r"broken\.log\.gz: cannot read as a CARMEN log"):
        load_map(path)
