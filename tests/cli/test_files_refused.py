"""Files written by other software, read right or refused in one line on every command:
``info`` shows a warning as ``pcmapq: warning: ...`` as ``inspect`` and ``eval`` do, and a LAZ
file whose decoder panics is one error line, not Rust's backtrace and Python's traceback."""

from __future__ import annotations

from pathlib import Path

import laspy
import numpy as np

from testkit.command import run, run_process


def test_info_shows_a_warning_as_pcmapq_s(tmp_path: Path) -> None:
    """An image whose YAML beside it names another image: read with that YAML, said in one
    warning line (Python's raw UserWarning with its source line before)."""
    import cv2

    image = np.full((20, 20), 254, np.uint8)
    image[5, 2:18] = 0
    cv2.imwrite(str(tmp_path / "a.png"), image)
    (tmp_path / "a.yaml").write_text("image: other.png\nresolution: 0.5\norigin: [0, 0, 0]\n")
    got = run("info", str(tmp_path / "a.png"))
    assert got.returncode == 0, got.stderr
    line, = got.stderr.splitlines()
    assert line.startswith(f"pcmapq: warning: {tmp_path / 'a.yaml'}: names image 'other.png'")
    assert "UserWarning" not in got.stderr and "0.5 m per pixel" in got.stdout


def test_a_laz_file_whose_decoder_panics_is_one_line(tmp_path: Path) -> None:
    """lazrs panics on a LASzip VLR that lists Point10 twice: exit 2 and one line (236 lines
    of Rust's backtrace and Python's traceback before)."""
    las = laspy.LasData(laspy.LasHeader(point_format=3, version="1.2"))
    las.x, las.y, las.z = np.random.default_rng(7).uniform(-4, 4, (400, 3)).T
    path = tmp_path / "panic.laz"
    las.write(path)
    data = bytearray(path.read_bytes())
    data[data.index(b"laszip encoded") - 2 + 54 + 40] = 6  # the second item: Point10
    path.write_bytes(data)
    got = run_process("info", str(path))
    assert got.returncode == 2 and got.stdout == ""
    line, = got.stderr.splitlines()
    assert line.startswith(f"pcmapq: error: {path}: not a readable LAS/LAZ file: its "
                           "compressed points are corrupt (the LAZ decoder failed")
