"""The loaders' fuzzing seeds (``tools/fuzz_loaders.py``; its recordings, slower to write: in
tests/e2e/test_fuzz_bags.py) load as they are, and one regression test for each crash or noise
the fuzzer found (the fuzzing itself, mutated seeds of every format:
tests/e2e/test_fuzz_loaders.py)."""

from __future__ import annotations

import struct
import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io import PointMap, load_map
from tools.fuzz_loaders import make_seeds, run_example

SEEDS = make_seeds(recordings=False)  # the recordings': tests/e2e/test_fuzz_bags.py


@pytest.mark.parametrize("name", sorted(SEEDS))
def test_each_seed_loads_as_it_is(tmp_path: Path, name: str,
                                  capfd: pytest.CaptureFixture[str]) -> None:
    """The fuzzer starts from sound files: unmutated, each loads, silently."""
    assert run_example(SEEDS[name], [], tmp_path) == "loaded"
    assert capfd.readouterr() == ("", "")


def _refused(path: Path, expected: str, capfd: pytest.CaptureFixture[str]) -> None:
    """``path`` gives one InputError line starting with the path and holding ``expected``, and
    nothing is printed."""
    capfd.readouterr()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError) as raised:
            load_map(path)
    message = str(raised.value)
    assert message.startswith(str(path)) and "\n" not in message, message
    assert expected in message, message
    assert capfd.readouterr() == ("", ""), "library output beside the error"


def _npy_with_header(path: Path, header: bytes) -> Path:
    """A .npy of 40 x 3 float64 whose header dictionary text is ``header`` (padded)."""
    body = header.ljust(118) + b"\n"
    path.write_bytes(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(body)) + body
                     + np.zeros((40, 3)).tobytes())
    return path


@pytest.mark.parametrize("header", [
    b"{'descr': '<f8', 'fortran_order': False, 'shape': (40, 3), ",  # SyntaxError
    b"{2147483647: '<f8', 'fortran_order': False, 'shape': (40, 3), }",  # TypeError
])
def test_npy_with_a_garbled_header_is_refused(tmp_path: Path, header: bytes,
                                              capfd: pytest.CaptureFixture[str]) -> None:
    _refused(_npy_with_header(tmp_path / "m.npy", header), "not a .npy file", capfd)


def test_a_signalling_nan_in_a_kitti_scan_drops_its_point_without_a_warning(
        tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    records = np.tile(np.array([1.0, 2.0, 3.0, 0.5], dtype="<f4"), (5, 1))
    records[:, 0] = np.arange(5)
    raw = bytearray(records.tobytes())
    raw[16:20] = struct.pack("<I", 0x7F800001)  # x of the second point: a signalling NaN
    path = tmp_path / "scan.bin"
    path.write_bytes(bytes(raw))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cloud = load_map(path)
    assert isinstance(cloud, PointMap)
    np.testing.assert_array_equal(cloud.points[:, 0], [0.0, 2.0, 3.0, 4.0])
    assert capfd.readouterr() == ("", "")


def _ascii_ply(path: Path, rows: list[str]) -> Path:
    path.write_text(f"ply\nformat ascii 1.0\nelement vertex {len(rows)}\nproperty float x\n"
                    "property float y\nproperty float z\nend_header\n" + "\n".join(rows) + "\n")
    return path


def _ply_with_faces(path: Path, first_count: int) -> Path:
    """A binary PLY of 4 triangles, then 30 vertices; the first face's list count is
    ``first_count``."""
    faces = b"".join(struct.pack("<Biii", first_count if i == 0 else 3, i, i + 1, i + 2)
                     for i in range(4))
    head = (b"ply\nformat binary_little_endian 1.0\nelement face 4\n"
            b"property list uchar int vertex_indices\nelement vertex 30\nproperty float x\n"
            b"property float y\nproperty float z\nend_header\n")
    path.write_bytes(head + faces + np.arange(90, dtype="<f4").tobytes())
    return path


@pytest.mark.parametrize("name", ["word", "faces"])
def test_a_ply_that_rply_cannot_parse_is_refused_without_its_message_on_stderr(
        tmp_path: Path, name: str, capfd: pytest.CaptureFixture[str]) -> None:
    """Open3D printed 'RPly: Error reading ...' and returned the cloud padded with zeros."""
    if name == "word":
        path = _ascii_ply(tmp_path / "m.ply", ["1 2 3", "4 abc 6", "7 8 9"])
        expected = "corrupt PLY: Error reading 'y' of 'vertex' number 1"
    else:
        path = _ply_with_faces(tmp_path / "m.ply", 200)
        expected = "corrupt PLY: Error reading value number"
    _refused(path, expected, capfd)


def test_a_sound_ply_with_faces_before_its_vertices_loads(tmp_path: Path) -> None:
    cloud = load_map(_ply_with_faces(tmp_path / "m.ply", 3))
    assert isinstance(cloud, PointMap)
    np.testing.assert_array_equal(cloud.points, np.arange(90).reshape(30, 3))


@pytest.mark.parametrize("data", [b"P5\n20 16\n25", b"P5\n20 16\n255\n" + bytes(100)],
                         ids=["header", "pixels"])
def test_a_truncated_pgm_is_refused_without_opencvs_error_line(
        tmp_path: Path, data: bytes, capfd: pytest.CaptureFixture[str]) -> None:
    """OpenCV printed '[ERROR:0@...] global loadsave.cpp ... can't read header/data'."""
    path = tmp_path / "m.pgm"
    path.write_bytes(data)
    _refused(path, "cannot be read as an image", capfd)


def _png(width: int | None = None, flip: int | None = None, keep: int | None = None) -> bytes:
    """A 24 x 32 grey PNG: its IHDR width replaced (CRC recomputed), a bit flipped at byte
    ``flip``, or cut to ``keep`` bytes."""
    import cv2
    image = np.full((24, 32), 254, dtype=np.uint8)
    image[4:20, 5] = 0
    data = bytearray(cv2.imencode(".png", image)[1].tobytes())
    if width is not None:
        data[16:20] = struct.pack(">I", width)
        data[29:33] = struct.pack(">I", zlib.crc32(bytes(data[12:29])))
    if flip is not None:
        data[flip] ^= 1
    return bytes(data[:keep])


@pytest.mark.parametrize(("data", "expected"), [
    (_png(flip=16), "corrupt PNG (CRC error in chunk 'IHDR' at byte 8)"),
    (_png(flip=45), "corrupt PNG (CRC error in chunk 'IDAT'"),
    (_png(keep=60), "truncated PNG (chunk 'IDAT' at byte 33"),
    (_png(width=1), "cannot be read as an image: libpng error: "),
], ids=["ihdr_crc", "idat_crc", "cut", "width"])
def test_a_corrupt_png_is_refused_without_libpngs_error_line(
        tmp_path: Path, data: bytes, expected: str, capfd: pytest.CaptureFixture[str]) -> None:
    """libpng printed 'libpng error: IHDR: CRC error', '... bad adaptive filter value'."""
    path = tmp_path / "m.png"
    path.write_bytes(data)
    _refused(path, expected, capfd)
