"""Survey clouds: LAS and LAZ written by laspy and E57 by pye57 read back as their points (E57
scans placed by their poses), refused naming the file when broken, truncated or larger than
the memory allows."""

from __future__ import annotations

import struct
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
    ("empty.e57", b"", "not a readable E57 file: empty"),
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


def test_a_layered_laz_file_reads_as_its_points(tmp_path):
    """LAS 1.4's point format 6, compressed in layers (of which x, y, z are decoded)."""
    las = laspy.LasData(laspy.LasHeader(point_format=6, version="1.4"))
    las.x, las.y, las.z = POINTS[:5000].T
    las.write(tmp_path / "cloud.laz")
    got = load_map(tmp_path / "cloud.laz")
    assert got.is_3d and np.abs(got.points - POINTS[:5000]).max() <= 0.005 + 1e-9  # 0.01 m


def small_laz(path: Path, point_format: int = 3, version: str = "1.2") -> bytearray:
    """The bytes of 400 points written by laspy as LAZ (point-wise chunks for format 3, layered
    for 6)."""
    las = laspy.LasData(laspy.LasHeader(point_format=point_format, version=version))
    las.x, las.y, las.z = np.random.default_rng(7).uniform(-4, 4, (400, 3)).T
    las.write(path)
    return bytearray(path.read_bytes())


def laszip_data(data: bytes) -> int:
    """Where the LASzip VLR's data starts."""
    return data.index(b"laszip encoded") - 2 + 54


def refused(path: Path, data: bytes, capfd: pytest.CaptureFixture[str]) -> str:
    """``data`` written to ``path`` and read: the InputError's message, one line naming the
    file, with nothing printed beside it."""
    path.write_bytes(data)
    capfd.readouterr()
    with pytest.raises(InputError) as raised:
        load_map(path)
    message = str(raised.value)
    assert message.startswith(f"{path}: ") and "\n" not in message, message
    assert capfd.readouterr() == ("", "")
    return message


def test_a_laz_file_whose_decoder_panics_is_refused_in_one_line(tmp_path, capfd):
    """Its items' list names Point10 twice: lazrs panics (a BaseException, its message and
    backtrace printed by Rust on stderr); one line, nothing printed."""
    data = small_laz(tmp_path / "a.laz")
    second_item = laszip_data(data) + 34 + 6
    assert data[second_item] == 7  # GPSTime
    data[second_item] = 6
    message = refused(tmp_path / "panic.laz", data, capfd)
    assert "its compressed points are corrupt (the LAZ decoder failed" in message


def test_a_las_file_cut_in_a_record_is_refused_as_truncated(tmp_path, capfd):
    las = laspy.LasData(laspy.LasHeader(point_format=3, version="1.2"))
    las.x, las.y, las.z = POINTS[:400].T
    las.write(tmp_path / "a.las")
    data = (tmp_path / "a.las").read_bytes()[:-10]
    message = refused(tmp_path / "cut.las", data, capfd)
    assert message.endswith("truncated: room for 399 of the 400 points its header declares")


def _chunk_table(data: bytes) -> int:
    """The chunk table's offset (the first 8 bytes of a LAZ file's point data)."""
    offset = struct.unpack_from("<I", data, 96)[0]
    return struct.unpack_from("<q", data, offset)[0]


@pytest.mark.parametrize(("point_format", "version"), [(3, "1.2"), (6, "1.4")])
def test_a_laz_chunk_table_declaring_billions_of_chunks_is_refused(tmp_path, capfd,
                                                                   point_format, version):
    """lazrs allocates an entry per declared chunk before reading any (52 GB, then the process
    ends): the count is checked against the bytes that hold the chunks."""
    data = small_laz(tmp_path / "a.laz", point_format, version)
    struct.pack_into("<I", data, _chunk_table(data) + 4, 2**31 + 1)
    message = refused(tmp_path / "chunks.laz", data, capfd)
    assert "its chunk table declares 2,147,483,649 chunks of compressed points" in message


def test_a_laz_layer_larger_than_the_file_is_refused(tmp_path, capfd):
    """A layered chunk's z layer declared 4 GB long: lazrs would fill 4 GB before reading it."""
    data = small_laz(tmp_path / "a.laz", 6, "1.4")
    start = struct.unpack_from("<I", data, 96)[0] + 8 + 30 + 4  # first point, point count
    struct.pack_into("<I", data, start + 4, 0xF0000000)
    message = refused(tmp_path / "layers.laz", data, capfd)
    assert "its compressed chunk 1 declares layers of" in message


def test_a_laz_file_cut_before_its_chunk_table_is_refused(tmp_path, capfd):
    data = small_laz(tmp_path / "a.laz", 6, "1.4")
    message = refused(tmp_path / "cut.laz", data[:_chunk_table(data) - 1], capfd)
    assert "its chunk table lies at byte" in message and "truncated or corrupt" in message


def test_extended_records_are_not_read(tmp_path):
    """A LAS 1.4 header declaring 8 million extended VLRs from byte 0: the points read as
    they are (laspy would parse the whole file as records)."""
    data = small_laz(tmp_path / "a.laz", 6, "1.4")
    struct.pack_into("<QI", data, 235, 0, 2**23)
    (tmp_path / "evlrs.laz").write_bytes(data)
    assert load_map(tmp_path / "evlrs.laz").points.shape == (400, 3)


def test_more_records_than_the_file_holds_are_refused_before_laspy_reads_them(tmp_path, capfd):
    """65,536 VLRs declared before points said to start past the file's end: laspy would
    parse each from nothing (seconds)."""
    data = small_laz(tmp_path / "a.laz")
    struct.pack_into("<II", data, 96, 2**31, 65536)  # offset to the points, VLRs
    message = refused(tmp_path / "vlrs.laz", data, capfd)
    assert "its header declares 65,536 variable-length records in" in message
