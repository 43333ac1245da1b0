"""Broken inputs, generated here, through the command line: truncated PLY/PCD/.npy, headers that
declare absurd sizes (.npy, PNG, PGM, CARMEN), degenerate maps. Each gives its exit code and one
line naming the file, no traceback, quickly and without allocating what the header declares."""

from __future__ import annotations

import io
import struct
import time
import zlib
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import open3d as o3d
import pytest
from numpy.lib import format as npy
from typer.testing import CliRunner

from pcmapq.cli import app
from testkit.carmen import flaser_log
from testkit.paths import SAMPLE

POINTS = np.random.default_rng(0).uniform(0.0, 5.0, (200, 3))


def _open3d(path: Path, **options: bool) -> Path:
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(POINTS))
    assert o3d.io.write_point_cloud(str(path), cloud, **options)
    return path


def _cut(path: Path, keep: float) -> Path:
    """The file cut to ``keep`` of its data (0: header only)."""
    raw = path.read_bytes()
    if path.suffix == ".ply":
        start = raw.index(b"end_header\n") + 11
    else:
        start = raw.index(b"\n", raw.index(b"DATA")) + 1
    path.write_bytes(raw[:start + int((len(raw) - start) * keep)])
    return path


def _npy_header(path: Path, shape: tuple[int, ...]) -> Path:
    buf = io.BytesIO()
    npy.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": shape})
    path.write_bytes(buf.getvalue() + np.zeros(6).tobytes())
    return path


def _png_header(path: Path, side: int) -> Path:
    def chunk(kind: bytes, body: bytes) -> bytes:
        crc = struct.pack(">I", zlib.crc32(kind + body))
        return struct.pack(">I", len(body)) + kind + body + crc
    ihdr = struct.pack(">IIBBBBB", side, side, 8, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b""))
    return path


CUT = "truncated: header declares 200 points"
PGM = b"P5\n# big\n1000000 1000000\n255\n" + bytes(9)

BROKEN: dict[str, tuple[Callable[[Path], Path], str]] = {
    "cut_ascii.ply": (lambda p: _cut(_open3d(p, write_ascii=True), 0.5), CUT),
    "head_ascii.ply": (lambda p: _cut(_open3d(p, write_ascii=True), 0.0), "the file holds 0"),
    "head_binary.ply": (lambda p: _cut(_open3d(p), 0.0), CUT + ", the file holds 0"),
    "cut_binary.ply": (lambda p: _cut(_open3d(p), 0.5), CUT),
    "cut_ascii.pcd": (lambda p: _cut(_open3d(p, write_ascii=True), 0.5), CUT),
    "head_binary.pcd": (lambda p: _cut(_open3d(p), 0.0), "the file holds 0"),
    "cut_binary.pcd": (lambda p: _cut(_open3d(p), 0.7), CUT),
    "cut_compressed.pcd": (lambda p: _cut(_open3d(p, compressed=True), 0.5), "truncated"),
    "rows_1e12.npy": (lambda p: _npy_header(p, (10**12, 3)), "shape (1000000000000, 3)"),
    "pixels_1e12.png": (lambda p: _png_header(p, 10**6), "1000000 x 1000000 pixels"),
    "pixels_1e12.pgm": (lambda p: p.write_bytes(PGM) and p,
                        "1000000 x 1000000 pixels"),
    "beams_1e8.log": (lambda p: p.write_text("FLASER 100000000 1 2 3\n") and p,
                      "FLASER with 100000000 beams needs 100000011 fields, got 5"),
}


def _eval(map_path: Path, *extra: str) -> tuple[int, str]:
    got = CliRunner().invoke(app, ["eval", str(map_path), str(SAMPLE / "truth.png"),
                                   "--map-resolution", "0.05", *extra])
    return got.exit_code, got.stderr


@pytest.mark.unit
@pytest.mark.parametrize("name", sorted(BROKEN))
def test_broken_file_is_one_line_exit_2_quickly(tmp_path: Path, name: str) -> None:
    make, expected = BROKEN[name]
    path = make(tmp_path / name)
    start = time.perf_counter()
    code, stderr = _eval(path)
    assert code == 2, stderr
    assert len(stderr.strip().splitlines()) == 1, stderr
    assert str(path) in stderr and expected in stderr, stderr
    assert "Traceback" not in stderr and "RPly" not in stderr
    assert time.perf_counter() - start < 10.0


def test_an_image_too_large_for_the_memory_guard_is_refused_before_decoding(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """30000 x 30000 pixels (a real, 1 MB PNG) under a 1 GB limit: refused from its header."""
    from pcmapq.core import memory
    path = tmp_path / "big.png"
    image = np.full((30000, 30000), 254, dtype=np.uint8)
    cv2.imwrite(str(path), image)
    del image
    monkeypatch.setattr(memory, "default_limit", lambda: 10**9)
    start = time.perf_counter()
    code, stderr = _eval(path)
    assert code == 2 and "30000 x 30000 pixels" in stderr and str(path) in stderr, stderr
    assert time.perf_counter() - start < 10.0


DEGENERATE: dict[str, Callable[[Path], Path]] = {
    "one.npy": lambda p: np.save(p, np.ones((1, 3))) or p,
    "three.npy": lambda p: np.save(p, np.full((3, 2), 2.5)) or p,
    "same_5000.npy": lambda p: np.save(p, np.tile([[1.0, 2.0, 0.0]], (5000, 1))) or p,
    "nine_cells.npy": lambda p: np.save(p, np.column_stack([np.arange(9) * 0.5, np.zeros(9)])) or p,
    "dot.png": lambda p: cv2.imwrite(str(p), np.zeros((1, 1), np.uint8)) and p,
}


@pytest.mark.unit
@pytest.mark.parametrize("name", sorted(DEGENERATE))
def test_degenerate_map_is_refused_with_exit_1(tmp_path: Path, name: str) -> None:
    path = DEGENERATE[name](tmp_path / name)
    code, stderr = _eval(path)
    assert code == 1, stderr
    assert len(stderr.strip().splitlines()) == 1 and str(path) in stderr, stderr
    assert "degenerate map" in stderr and "fewer than 10" in stderr, stderr


def _tiny_log(path: Path) -> Path:
    """A CARMEN log of three scans in the sample's hall: a run for `pcmapq track`."""
    poses = np.array([[6.0, 8.0, 0.0], [6.5, 8.0, 0.0], [7.0, 8.0, 0.0]])
    return flaser_log(path, np.full((3, 181), 3.0), poses)


#: Every command that reads a map or a truth, as (name, arguments for the broken file).
COMMANDS: dict[str, Callable[[Path, Path], list[str]]] = {
    "eval truth": lambda bad, tmp: ["eval", str(SAMPLE / "truth.png"), str(bad),
                                    "--truth-resolution", "0.05"],
    "inspect": lambda bad, tmp: ["inspect", str(bad), "--map-resolution", "0.05"],
    "track truth": lambda bad, tmp: ["track", str(_tiny_log(tmp / "run.log")), str(bad),
                                     "--truth-resolution", "0.05", "--out", str(tmp / "t")],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize("name", ["cut_binary.ply", "rows_1e12.npy", "pixels_1e12.png",
                                  "beams_1e8.log"])
def test_every_command_refuses_a_broken_file_in_one_line(tmp_path: Path, name: str,
                                                         command: str) -> None:
    """The broken files of eval's map side, given to eval as the truth, to inspect and to
    track as the truth: exit 2, one line naming the file and the problem, no traceback."""
    make, expected = BROKEN[name]
    path = make(tmp_path / name)
    got = CliRunner().invoke(app, COMMANDS[command](path, tmp_path))
    assert got.exit_code == 2, got.stderr
    assert len(got.stderr.strip().splitlines()) == 1, got.stderr
    assert str(path) in got.stderr and expected in got.stderr, got.stderr
    assert "Traceback" not in got.stderr


def test_a_broken_map_fails_its_batch_row_with_the_same_line(tmp_path: Path) -> None:
    """`pcmapq batch`: a truncated PLY among the maps fails its row (exit 1) with the line eval
    gives; the other row is scored."""
    make, expected = BROKEN["cut_binary.ply"]
    path = make(tmp_path / "cut_binary.ply")
    got = CliRunner().invoke(app, ["batch", str(path), str(SAMPLE / "scan.ply"), "--truth",
                                   str(SAMPLE / "truth.png"), "--out", str(tmp_path / "b"),
                                   "--workers", "1", "--quiet"])
    assert got.exit_code == 1, got.stderr
    table = (tmp_path / "b" / "table.csv").read_text()
    assert expected in table and expected in got.stderr, (table, got.stderr)
    assert "Traceback" not in table + got.stderr and (tmp_path / "b" / "scan.json").is_file()


def test_grey_walls_get_the_threshold_that_would_read_them(tmp_path: Path) -> None:
    """The sample's plan with its walls drawn grey (128, p = 0.50, as a CARMEN map draws them):
    the line says how dark its darkest pixels read and which option marks them; with it, the
    evaluation runs."""
    image = cv2.imread(str(SAMPLE / "truth.png"), cv2.IMREAD_GRAYSCALE)
    image[image == 0] = 128
    cv2.imwrite(str(tmp_path / "grey.png"), image)
    got = CliRunner().invoke(app, ["eval", str(SAMPLE / "scan.ply"), str(tmp_path / "grey.png"),
                                   "--truth-resolution", "0.05"])
    assert got.exit_code == 2 and len(got.stderr.strip().splitlines()) == 1, got.stderr
    assert "p = 0.50" in got.stderr and "--truth-occupied-thresh" in got.stderr, got.stderr
    got = CliRunner().invoke(app, ["eval", str(SAMPLE / "scan.ply"), str(tmp_path / "grey.png"),
                                   "--truth-resolution", "0.05", "--truth-occupied-thresh",
                                   "0.4", "--force", "--quiet"])
    assert got.exit_code == 0, got.stderr


@pytest.mark.unit
def test_two_images_without_resolution_are_both_named(tmp_path: Path) -> None:
    for name in ("a.png", "b.png"):
        (tmp_path / name).write_bytes((SAMPLE / "truth.png").read_bytes())
    got = CliRunner().invoke(app, ["eval", str(tmp_path / "a.png"), str(tmp_path / "b.png")])
    assert got.exit_code == 2 and len(got.stderr.strip().splitlines()) == 1, got.stderr
    assert all(str(tmp_path / n) in got.stderr for n in ("a.png", "b.png")), got.stderr
    assert "--map-resolution and --truth-resolution" in got.stderr
