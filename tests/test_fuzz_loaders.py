"""Fuzzing of every loader (``tools/fuzz_loaders.py``, bounded here to about a minute): mutated
seed files of each format either load with the documented invariants or raise one InputError
line naming the file, with nothing on stdout or stderr; and one regression test for each crash
or noise the fuzzer found."""

from __future__ import annotations

import io
import struct
import warnings
import zlib
from pathlib import Path

import numpy as np
import pytest
from numpy.lib import format as npy

from pcmapq.errors import InputError
from pcmapq.io import PointMap, load_map


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


@pytest.mark.unit
@pytest.mark.parametrize("header", [
    b"{'descr': '<f8', 'fortran_order': False, 'shape': (40, 3), ",  # SyntaxError (TokenError for others)
    b"{2147483647: '<f8', 'fortran_order': False, 'shape': (40, 3), }",  # TypeError
])
def test_npy_with_a_garbled_header_is_refused(tmp_path: Path, header: bytes,
                                              capfd: pytest.CaptureFixture[str]) -> None:
    _refused(_npy_with_header(tmp_path / "m.npy", header), "not a .npy file", capfd)


@pytest.mark.unit
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
