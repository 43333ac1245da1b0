"""Fuzzing of every map and pose loader: valid small seed files of each format, mutated (byte
flips, insertions, deletions, truncation, header fields and YAML values replaced by absurd ones),
each read by :func:`pcmapq.io.load_map` or a pose reader; a ROS recording (ROS 1 bag, ROS 2
bag of SQLite or MCAP storage, a zstd-compressed MCAP) by every reader of recordings: its map,
its scans and the odometry placing them (:func:`read_recording`). The only outcomes allowed are
a load whose result holds the documented invariants or an :class:`InputError` of one line
starting with the file's path; anything else (another exception, a slow read, a large
allocation, output on stdout or stderr, a warning other than pcmapq's own about a recording) is
a finding.

``tests/e2e/test_fuzz_loaders.py`` runs this for about a minute in CI; from the command line
it runs longer and prints the examples run and the outcomes per format::

    python -m tools.fuzz_loaders [--minutes 10] [--seed 0] [--formats ply_binary,pcd_ascii]
"""

from __future__ import annotations

import argparse
import gzip
import io
import os
import resource
import signal
import struct
import sys
import tempfile
import time
import warnings
import zlib
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from hypothesis import strategies as st

from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.mapping.poses import read_calib, read_poses

#: Longest a single load may take, seconds.
TIME_LIMIT = 5.0
#: Largest growth of the process's peak resident memory a single load may cause, bytes.
MEMORY_LIMIT = 200 << 20

#: Values a header field or a YAML value is replaced by.
ODD_VALUES = (
    "0", "1", "-1", "2", "3", "-3", "7", "255", "256", "65536", "2147483647", "2147483648",
    "4294967295", "4294967296", "-2147483649", "9223372036854775807", "18446744073709551616",
    "99999999999999999999999", "1e9", "1e300", "1e400", "-1e300", "1.5", "0.5", "-0.0", "5e-2",
    "nan", "NaN", "inf", "-inf", ".nan", ".inf", "-.inf", "1e-320", "0x10", "abc", "", "''",
    "null", "~", "true", "yes", "[]", "[1, 2]", "[nan, 0, 0]", "[1e308, -1e308, 1e308]",
    "[0, 0, 0, 0]", "{a: 1}", "[[1]]", "!!binary AAAA", "&a 1", "*a", "x: y", "- 1", "'text'",
    "float", "double", "uchar", "char", "int", "uint", "list", "F", "I", "U", "x", "y", "z",
    "ascii", "binary", "binary_compressed", "binary_big_endian", "FLASER", "vertex", "face",
    "\x00", "\xff", "\t", "\n", "#", "%", "\u00e9", "  ",
)


@dataclass(frozen=True)
class Seed:
    """A valid input: ``files`` written into a folder; ``target`` is the file mutated,
    ``entry`` the file given to ``reader``; ``header`` gives the end of the target's text header
    (the region whose tokens field edits replace); ``decode`` turns the target's contents into
    the bytes mutated (gunzip), ``encode`` the mutated bytes into the file's contents (gzip;
    an E57's page checksums made right again, so that mutations reach its parser)."""

    name: str
    files: dict[str, bytes]
    target: str
    entry: str
    reader: str = "map"
    header: Callable[[bytes], int] = len
    encode: Callable[[bytes], bytes] | None = None
    decode: Callable[[bytes], bytes] | None = None


@dataclass
class Tally:
    """Examples run and their outcomes, per seed."""

    runs: Counter[str] = field(default_factory=Counter)
    outcomes: dict[str, Counter[str]] = field(default_factory=dict)

    def add(self, seed: str, outcome: str) -> None:
        """Count one example of ``seed`` ending in ``outcome``."""
        self.runs[seed] += 1
        self.outcomes.setdefault(seed, Counter())[outcome] += 1


class Finding(AssertionError):
    """A loader broke its contract on a mutated input."""


# ---- seeds ---------------------------------------------------------------------------------

def _open3d_bytes(suffix: str, **options: bool) -> bytes:
    import open3d as o3d

    points = np.random.default_rng(1).uniform(-4.0, 4.0, (60, 3))
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"seed{suffix}"
        assert o3d.io.write_point_cloud(str(path), cloud, **options)
        return path.read_bytes()


def _ply_with_faces() -> bytes:
    """A binary PLY whose faces (a list property) come before its vertices: Open3D reads it."""
    points = np.random.default_rng(2).uniform(-4.0, 4.0, (30, 3)).astype("<f4")
    faces = b"".join(struct.pack("<Biii", 3, i, i + 1, i + 2) for i in range(4))
    head = (b"ply\nformat binary_little_endian 1.0\nelement face 4\n"
            b"property list uchar int vertex_indices\nelement vertex 30\nproperty float x\n"
            b"property float y\nproperty float z\nend_header\n")
    return head + faces + points.tobytes()


def _npy_bytes(points: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, points)
    return buf.getvalue()


def _png_bytes() -> bytes:
    import cv2

    image = np.full((24, 32), 254, dtype=np.uint8)
    image[4:20, 5] = 0
    image[4, 5:28] = 0
    image[15:, 20:] = 205
    ok, data = cv2.imencode(".png", image)
    assert ok
    return data.tobytes()


def _pgm_bytes() -> bytes:
    image = np.full((16, 20), 254, dtype=np.uint8)
    image[3:13, 4] = 0
    return b"P5\n# seed\n20 16\n255\n" + image.tobytes()


YAML = ("image: {image}\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n")


def _carmen_text() -> str:
    rng = np.random.default_rng(3)
    lines = ["# message formats defined: PARAM SYNC ODOM FLASER RLASER",
             "PARAM robot_frontlaser_offset 0.0 nohost 0",
             "ODOM 0.0 0.0 0.0 0 0 0 1.0 nohost 1.0"]
    for k, n in enumerate((5, 5, 7)):
        ranges = " ".join(f"{r:.3f}" for r in rng.uniform(0.5, 6.0, n))
        lines.append(f"FLASER {n} {ranges} {k * 0.5} 0.1 0.2 {k * 0.5} 0.1 0.2 {k + 1.5} "
                     f"pippo {k + 1.5}")
    return "\n".join(lines) + "\nNEFF 1 2 3\n"


def _poses_text(kind: str) -> str:
    rng = np.random.default_rng(4)
    if kind == "tum":
        rows = [[k, *rng.uniform(-2, 2, 3), *(q / np.linalg.norm(q))]
                for k, q in enumerate(rng.normal(size=(4, 4)))]
    else:
        rows = [[1, 0, 0, x, 0, 1, 0, 0.5 * x, 0, 0, 1, 0.1] for x in range(4)]
    return "".join(" ".join(repr(float(v)) for v in row) + "\n" for row in rows)


def _file_bytes(name: str, write: Callable[[Path], object]) -> bytes:
    """The bytes a writer puts into a file named ``name`` (written in a temporary folder)."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / name
        write(path)
        return path.read_bytes()


def _las_bytes(suffix: str, point_format: int = 3, version: str = "1.2") -> bytes:
    """A LAS or LAZ file (by ``suffix``) of 40 points written by laspy: point format 3 is
    compressed in point-wise chunks, 6 (LAS 1.4) in layered ones."""
    import laspy

    def write(path: Path) -> None:
        points = np.random.default_rng(7).uniform(-4, 4, (40, 3))
        las = laspy.LasData(laspy.LasHeader(point_format=point_format, version=version))
        las.x, las.y, las.z = points.T
        las.write(path)
    return _file_bytes(f"m{suffix}", write)


def _e57_bytes() -> bytes:
    """An E57 file of two scans of 20 points, the second placed by a pose, written by pye57."""
    import pye57

    def write(path: Path) -> None:
        points = np.random.default_rng(8).uniform(-4, 4, (40, 3))
        e57 = pye57.E57(str(path), mode="w")
        for k, part in enumerate((points[:20], points[20:])):
            e57.write_scan_raw({"cartesianX": part[:, 0], "cartesianY": part[:, 1],
                                "cartesianZ": part[:, 2]}, translation=np.array([k, 0.0, 0.0]),
                               rotation=np.array([1.0, 0.0, 0.0, 0.0]))
        e57.close()
    return _file_bytes("m.e57", write)


#: An E57 file's physical pages: 1020 bytes of data, then their CRC-32C (big-endian).
E57_PAGE, E57_DATA = 1024, 1020


def _crc_table(polynomial: int = 0x82F63B78) -> list[int]:
    """The byte table of a reflected CRC-32 (Castagnoli's polynomial by default)."""
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = (crc >> 1) ^ (polynomial & -(crc & 1))
        table.append(crc)
    return table


_CRC32C = _crc_table()


def _crc32c(data: bytes) -> int:
    """CRC-32C (Castagnoli) of ``data``, as E57 pages carry it."""
    crc = 0xFFFFFFFF
    for byte in data:
        crc = _CRC32C[(crc ^ byte) & 0xFF] ^ (crc >> 8)
    return crc ^ 0xFFFFFFFF


def e57_checksummed(data: bytes) -> bytes:
    """``data`` with the checksum of each whole E57 page set to its data's (a short last page
    left as it is)."""
    out = bytearray(data)
    for start in range(0, len(out) - E57_PAGE + 1, E57_PAGE):
        crc = _crc32c(bytes(out[start:start + E57_DATA]))
        out[start + E57_DATA:start + E57_PAGE] = crc.to_bytes(4, "big")
    return bytes(out)


def _mcap_bytes() -> bytes:
    from pcmapq.core.grid import MetricGrid
    from testkit.recordings import write_recording

    state = np.full((12, 16), FREE, dtype=np.int8)
    state[0, :], state[:, 0], state[5:7, 5:9] = OCCUPIED, OCCUPIED, UNKNOWN
    grid = MetricGrid(0.05, (0.0, 0.0, 0.0), state.shape)
    return _file_bytes("m.mcap", lambda path: write_recording(path, [(1.0, state, grid)],
                                                              "mcap"))


def _recording_files(layout: str, name: str) -> dict[str, bytes]:
    """A small recording of every message pcmapq reads (a 12 x 16 map, three 20-beam laser
    scans, the odometry and transforms placing them) written by rosbags in ``layout``, as
    its files by name (a ROS 2 bag: ``name/metadata.yaml`` and its storage file)."""
    from pcmapq.core.grid import MetricGrid
    from testkit.recordings import Scan, write_recording

    state = np.full((12, 16), FREE, dtype=np.int8)
    state[0, :], state[:, 0], state[5:7, 5:9] = OCCUPIED, OCCUPIED, UNKNOWN
    grid = MetricGrid(0.05, (0.0, 0.0, 0.0), state.shape)
    ranges = np.random.default_rng(8).uniform(0.5, 6.0, (3, 20))
    ranges[:, 3] = np.nan
    poses = []
    for k in range(3):
        pose = np.eye(4)
        pose[:2, 3] = 0.3 * k, 0.1 * k
        poses.append((1.0 + 0.25 * k, pose))
    with tempfile.TemporaryDirectory() as folder:
        path = write_recording(Path(folder) / name, [(1.0, state, grid)], layout,
                               scans=[Scan(t, r, -1.0, 0.1) for (t, _), r in zip(
                                   poses, ranges, strict=True)], poses=poses,
                               transforms=[(t, "odom", "laser", p) for t, p in poses])
        files = [path] if path.is_file() else sorted(path.iterdir())
        return {str(f.relative_to(folder)): f.read_bytes() for f in files}


def _zstd(data: bytes) -> bytes:
    from pcmapq.io.bag_files import zstd_module

    return zstd_module().compress(data)


def _unzstd(data: bytes) -> bytes:
    from pcmapq.io.bag_files import zstd_module

    return zstd_module().decompress(data)


def _after(marker: bytes) -> Callable[[bytes], int]:
    """The header ends after the line holding ``marker``."""
    def end(data: bytes) -> int:
        at = data.find(marker)
        return len(data) if at < 0 else data.find(b"\n", at) + 1 or len(data)
    return end


def recording_seeds() -> dict[str, Seed]:
    """The seed recordings, by name (each read by :func:`read_recording`); deterministic."""
    ros1, sqlite = _recording_files("ros1", "r.bag"), _recording_files("ros2-sqlite", "r")
    mcap, solo = _recording_files("ros2-mcap", "r"), _recording_files("mcap", "r.mcap")
    seeds = [
        Seed("ros1_bag", ros1, "r.bag", "r.bag", reader="recording", header=lambda d: 0),
        Seed("ros2_sqlite", sqlite, "r/r.db3", "r", reader="recording", header=lambda d: 0),
        Seed("ros2_mcap", mcap, "r/r.mcap", "r", reader="recording", header=lambda d: 0),
        Seed("ros2_metadata", mcap, "r/metadata.yaml", "r", reader="recording"),
        Seed("mcap_zstd", {"r.mcap.zstd": _zstd(solo["r.mcap"])}, "r.mcap.zstd",
             "r.mcap.zstd", reader="recording", header=lambda d: 0, encode=_zstd,
             decode=_unzstd),
    ]
    return {s.name: s for s in seeds}


def make_seeds(recordings: bool = True) -> dict[str, Seed]:
    """The seed inputs, by name (with ``recordings``, :func:`recording_seeds` too: a few
    seconds to write); deterministic."""
    ply_head, pcd_head = _after(b"end_header"), _after(b"DATA")
    kitti_points = np.random.default_rng(5).uniform(-4, 4, (40, 4)).astype("<f4")
    text_cloud = "".join(f"{x:.4f} {y:.4f} {z:.4f}\n" for x, y, z in
                         np.random.default_rng(6).uniform(-4, 4, (40, 3)))
    carmen = _carmen_text().encode()
    seeds = [
        Seed("ply_binary", {"m.ply": _open3d_bytes(".ply")}, "m.ply", "m.ply", header=ply_head),
        Seed("ply_ascii", {"m.ply": _open3d_bytes(".ply", write_ascii=True)}, "m.ply", "m.ply",
             header=ply_head),
        Seed("ply_faces", {"m.ply": _ply_with_faces()}, "m.ply", "m.ply", header=ply_head),
        Seed("pcd_ascii", {"m.pcd": _open3d_bytes(".pcd", write_ascii=True)}, "m.pcd", "m.pcd",
             header=pcd_head),
        Seed("pcd_binary", {"m.pcd": _open3d_bytes(".pcd")}, "m.pcd", "m.pcd", header=pcd_head),
        Seed("pcd_compressed", {"m.pcd": _open3d_bytes(".pcd", compressed=True)}, "m.pcd",
             "m.pcd", header=pcd_head),
        Seed("xyz", {"m.xyz": text_cloud.encode()}, "m.xyz", "m.xyz"),
        Seed("txt_csv", {"m.txt": text_cloud.replace(" ", ",").encode()}, "m.txt", "m.txt"),
        Seed("npy", {"m.npy": _npy_bytes(kitti_points[:, :3].astype(np.float64))}, "m.npy",
             "m.npy", header=_after(b"}")),
        Seed("kitti_bin", {"m.bin": kitti_points.tobytes()}, "m.bin", "m.bin", header=lambda d: 0),
        Seed("carmen", {"m.log": carmen}, "m.log", "m.log"),
        Seed("carmen_gz", {"m.log.gz": gzip.compress(carmen, mtime=0)}, "m.log.gz", "m.log.gz",
             encode=lambda data: gzip.compress(data, mtime=0), decode=gzip.decompress),
        Seed("png_image", {"m.png": _png_bytes(), "m.yaml": YAML.format(image="m.png").encode()},
             "m.png", "m.yaml", header=lambda d: 0),
        Seed("png_yaml", {"m.png": _png_bytes(), "m.yaml": YAML.format(image="m.png").encode()},
             "m.yaml", "m.yaml"),
        Seed("pgm_image", {"m.pgm": _pgm_bytes(), "m.yaml": YAML.format(image="m.pgm").encode()},
             "m.pgm", "m.pgm", header=_after(b"255")),
        Seed("las", {"m.las": _las_bytes(".las")}, "m.las", "m.las", header=lambda d: 0),
        Seed("laz", {"m.laz": _las_bytes(".laz")}, "m.laz", "m.laz", header=lambda d: 0),
        Seed("laz_layered", {"m.laz": _las_bytes(".laz", 6, "1.4")}, "m.laz", "m.laz",
             header=lambda d: 0),
        Seed("e57", {"m.e57": _e57_bytes()}, "m.e57", "m.e57", header=lambda d: 0,
             encode=e57_checksummed),
        Seed("mcap_grid", {"m.mcap": _mcap_bytes()}, "m.mcap", "m.mcap", header=lambda d: 0),
        Seed("kitti_poses", {"p.txt": _poses_text("kitti").encode()}, "p.txt", "p.txt",
             reader="poses"),
        Seed("tum_poses", {"p.txt": _poses_text("tum").encode()}, "p.txt", "p.txt",
             reader="poses"),
        Seed("calib", {"c.txt": b"P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n"},
             "c.txt", "c.txt", reader="calib"),
    ]
    return {s.name: s for s in seeds} | (recording_seeds() if recordings else {})


def original(seed: Seed) -> bytes:
    """The bytes mutations apply to: the target's contents, decoded (gunzipped) if need be."""
    data = seed.files[seed.target]
    return seed.decode(data) if seed.decode else data


# ---- mutations -----------------------------------------------------------------------------

#: One mutation: (kind, position, amount, bytes); positions wrap around the data's length.
Op = tuple[str, int, int, bytes]

_POSITION = st.integers(0, 1 << 20)
OPS = st.one_of(
    st.tuples(st.just("flip"), _POSITION, st.integers(0, 7), st.just(b"")),
    st.tuples(st.just("set"), _POSITION, st.integers(0, 255), st.just(b"")),
    st.tuples(st.just("insert"), _POSITION, st.just(0), st.binary(min_size=1, max_size=8)),
    st.tuples(st.just("delete"), _POSITION, st.integers(1, 64), st.just(b"")),
    st.tuples(st.just("truncate"), _POSITION, st.just(0), st.just(b"")),
    st.tuples(st.just("repeat"), _POSITION, st.integers(1, 256), st.just(b"")),
    st.tuples(st.just("field"), _POSITION, st.integers(0, len(ODD_VALUES) - 1), st.just(b"")),
    st.tuples(st.just("ihdr"), st.integers(0, 4), st.integers(0, 10),
              st.sampled_from([b"\x00", b"\x01", b"\x02", b"\x03", b"\x04", b"\x06", b"\x07",
                               b"\x08", b"\x10", b"\xff"])),
)
#: A mutation: one to three operations, applied in order.
MUTATIONS = st.lists(OPS, min_size=1, max_size=3)


def mutate(data: bytes, ops: list[Op], header: Callable[[bytes], int]) -> bytes:
    """``data`` with the operations applied in order (see :data:`OPS`)."""
    for kind, pos, amount, extra in ops:
        at = pos % (len(data) + 1)
        if kind == "flip" and data:
            at %= len(data)
            data = data[:at] + bytes([data[at] ^ (1 << amount)]) + data[at + 1:]
        elif kind == "set" and data:
            at %= len(data)
            data = data[:at] + bytes([amount]) + data[at + 1:]
        elif kind == "insert":
            data = data[:at] + extra + data[at:]
        elif kind == "delete":
            data = data[:at] + data[at + amount:]
        elif kind == "truncate":
            data = data[:at]
        elif kind == "repeat":
            data = data[:at + amount] + data[at:]
        elif kind == "field":
            data = _replace_token(data, pos, ODD_VALUES[amount].encode(), header(data))
        elif kind == "ihdr":
            data = _edit_ihdr(data, pos, amount, extra)
    return data


def _replace_token(data: bytes, pos: int, value: bytes, end: int) -> bytes:
    """``data`` with its token number ``pos`` (modulo their count; tokens are split at
    whitespace, ``:``, ``,`` and brackets, within the first ``end`` bytes) replaced."""
    import re

    spans = [m.span() for m in re.finditer(rb"[^\s:,\[\]{}()]+", data[:max(end, 0)][:1 << 16])]
    if not spans:
        return data
    start, stop = spans[pos % len(spans)]
    return data[:start] + value + data[stop:]


def _edit_ihdr(data: bytes, which: int, scale: int, value: bytes) -> bytes:
    """A PNG with one IHDR field (width, height, bit depth, colour type, interlace) replaced,
    its CRC recomputed; other data unchanged."""
    if not data.startswith(b"\x89PNG\r\n\x1a\n") or len(data) < 33 or data[12:16] != b"IHDR":
        return data
    body = bytearray(data[16:29])
    if which < 2:  # width or height: a power of ten or of two
        size = (10 ** scale if value[0] % 2 else 1 << (3 * scale)) & 0xFFFFFFFF
        body[4 * which:4 * which + 4] = struct.pack(">I", size)
    else:
        body[6 + which] = value[0]
    crc = struct.pack(">I", zlib.crc32(b"IHDR" + bytes(body)))
    return data[:16] + bytes(body) + crc + data[33:]


# ---- one example ---------------------------------------------------------------------------

class _Slow(BaseException):
    """Raised by the alarm: a load took longer than :data:`TIME_LIMIT`."""


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`_Slow` in the block after ``seconds`` (main thread, Python code only)."""
    def alarm(signum: int, frame: object) -> None:
        raise _Slow()
    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def write_example(seed: Seed, ops: list[Op], folder: Path) -> Path:
    """Write the seed's files into ``folder``, the target mutated; the entry's path."""
    for name, data in seed.files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)
    data = mutate(original(seed), ops, seed.header)
    (folder / seed.target).write_bytes(seed.encode(data) if seed.encode else data)
    return folder / seed.entry


def load(seed: Seed, path: Path) -> object:
    """Read ``path`` with the seed's reader."""
    if seed.reader == "poses":
        return read_poses(path)
    if seed.reader == "calib":
        return read_calib(path)
    if seed.reader == "recording":
        return read_recording(path)
    return load_map(path)


@dataclass(frozen=True)
class RecordingRead:
    """What each reader of a recording gave (None: it refused, with ``errors``' line)."""

    map: OccupancyMap | None
    poses: np.ndarray | None
    scans: list[np.ndarray] | None
    errors: tuple[InputError, ...]


def read_recording(path: Path) -> RecordingRead:
    """Read a recording as pcmapq's commands do: its map (``load_map``), the odometry at its
    scans' times (``recorded_poses``, /odom) and its scans (``open_scans``), each on its own;
    InputError (the first) when every one refuses it; :class:`Finding` for a refusal not one
    line naming the file."""
    from pcmapq.mapping import open_scans, recorded_poses

    readers = (lambda: load_map(path), lambda: recorded_poses(path, None, "/odom"),
               lambda: [points for points, _ in open_scans(path)])
    got: list[object] = []
    errors: list[InputError] = []
    for reader in readers:
        try:
            got.append(reader())
        except InputError as error:
            if "\n" in str(error) or not str(error).startswith(str(path)):
                raise Finding(f"InputError not one line naming the file: {str(error)!r}"
                              ) from None
            got.append(None)
            errors.append(error)
    if len(errors) == len(readers):
        raise errors[0]
    return RecordingRead(*got, tuple(errors))


def run_example(seed: Seed, ops: list[Op], folder: Path) -> str:
    """Write and read one mutated input: its outcome (``loaded`` or ``InputError``). Raises
    :class:`Finding` when the loader breaks its contract: another exception, a warning, an
    error message of several lines or not starting with the path, a result without its
    invariants, a load over :data:`TIME_LIMIT`, or a rise of the process's peak resident memory
    over :data:`MEMORY_LIMIT` (a high-water mark: a large allocation is seen once it exceeds
    every earlier peak). Output on fd 1 or 2 is the caller's to check."""
    path = write_example(seed, ops, folder)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught, time_limit(TIME_LIMIT):
            warnings.simplefilter("always")
            result = load(seed, path)
    except InputError as error:
        outcome, result = "InputError", None
        message = str(error)
        named = (str(path), str(folder / seed.target))  # the YAML, or the image it names
        if "\n" in message or not message.startswith(named):
            raise Finding(f"InputError not one line naming the file: {message!r}") from None
    except _Slow:
        raise Finding(f"load took more than {TIME_LIMIT} s") from None
    except KeyboardInterrupt:
        raise
    except BaseException as error:  # noqa: BLE001 - any other, a Rust panic's among them
        raise Finding(f"{type(error).__name__}: {error}") from error
    else:
        outcome = "loaded"
    elapsed = time.perf_counter() - start
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - before
    if seed.reader == "recording":  # pcmapq's own warnings (poses far from the scans) are said
        caught = [w for w in caught if not _own_warning(w)]
    if caught:
        w = caught[0]
        raise Finding(f"warning at {Path(w.filename).name}:{w.lineno}: "
                      f"{w.category.__name__}: {w.message}")
    if grown > MEMORY_LIMIT:
        raise Finding(f"peak memory grew by {grown / 1e6:.0f} MB")
    if elapsed > TIME_LIMIT:
        raise Finding(f"load took {elapsed:.1f} s")
    if result is not None:
        check_result(seed, result)
    return outcome


def _own_warning(w: warnings.WarningMessage) -> bool:
    """A warning pcmapq gives in words (``pcmapq: warning: ...`` on the command line)."""
    import pcmapq

    return w.category is UserWarning and w.filename.startswith(str(Path(pcmapq.__file__).parent))


def check_result(seed: Seed, result: object) -> None:
    """Raise :class:`Finding` unless a loaded result holds its documented invariants."""
    if isinstance(result, RecordingRead):
        for part in (result.map, result.poses):
            if part is not None:
                check_result(replace(seed, reader="poses" if part is result.poses else "map"),
                             part)
        for points in result.scans or []:
            _require(points.ndim == 2 and points.shape[1] == 3, f"scan of shape {points.shape}")
            _require(bool(np.isfinite(points).all()), "non-finite scan point")
        return
    if seed.reader == "poses":
        poses = result  # type: ignore[assignment]
        _require(poses.ndim == 3 and poses.shape[1:] == (4, 4) and len(poses) > 0,
                 f"poses of shape {poses.shape}")
        _require(np.isfinite(poses).all(), "non-finite pose")
    elif seed.reader == "calib":
        _require(result.shape == (4, 4) and np.isfinite(result).all(),  # type: ignore[attr-defined]
                 "calibration not a finite 4x4")
    elif isinstance(result, PointMap):
        points = result.points
        _require(points.ndim == 2 and points.shape[1] == 3 and len(points) > 0,
                 f"points of shape {points.shape}")
        _require(points.dtype in (np.float64, np.float32), f"points of type {points.dtype}")
        _require(bool(np.isfinite(points).all()), "non-finite point")
        _require(result.is_3d or not points[:, 2].any(), "2D cloud with z != 0")
    elif isinstance(result, OccupancyMap):
        state, grid = result.state, result.grid
        _require(state.ndim == 2 and state.dtype == np.int8 and state.size > 0,
                 f"state {state.dtype} {state.shape}")
        _require(bool(np.isin(state, (FREE, OCCUPIED, UNKNOWN)).all()), "unknown cell state")
        _require(tuple(grid.shape) == state.shape, f"grid {grid.shape} != state {state.shape}")
        _require(np.isfinite(grid.resolution) and grid.resolution > 0,
                 f"resolution {grid.resolution}")
        _require(bool(np.isfinite(grid.origin).all()), f"origin {grid.origin}")
    else:
        raise Finding(f"unexpected result {type(result).__name__}")


def _require(ok: bool, problem: str) -> None:
    if not ok:
        raise Finding(problem)


# ---- the long form -------------------------------------------------------------------------

@contextmanager
def captured_fds() -> Iterator[Callable[[], bytes]]:
    """Redirect fd 1 and 2 to a temporary file; yields a function returning (and clearing)
    what was written since its last call."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)

        def take() -> bytes:
            sys.stdout.flush()
            sys.stderr.flush()
            sink.seek(0)
            text = sink.read()
            sink.seek(0)
            sink.truncate()
            return text
        try:
            yield take
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])


def fuzz(seeds: list[Seed], seconds: float, first_seed: int, batch: int = 200) -> tuple[
        Tally, list[str]]:
    """Fuzz each seed for ``seconds`` / len(seeds), in Hypothesis runs of ``batch`` examples
    with seeds ``first_seed``, ``first_seed + 1``, ...; the tally and the findings, one per
    failing run (the seed's name, the problem and the shrunk mutation)."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import seed as hypothesis_seed

    tally, findings = Tally(), []
    share = seconds / len(seeds)
    for s in seeds:
        stop = time.monotonic() + share
        run = first_seed
        while time.monotonic() < stop:
            with tempfile.TemporaryDirectory() as tmp, captured_fds() as take:
                prop = given(MUTATIONS)(_example_checker(s, Path(tmp), tally, take))
                prop = settings(max_examples=batch, deadline=None, database=None,
                                suppress_health_check=list(HealthCheck))(prop)
                try:
                    hypothesis_seed(run)(prop)()
                except Exception as error:  # noqa: BLE001 - a Finding, or several
                    for found in getattr(error, "exceptions", [error]):
                        tally.add(s.name, "finding")
                        findings.append(f"{s.name}: {_describe(found)}")
            run += 1
    return tally, findings


def _describe(found: BaseException) -> str:
    """A finding in one line: its problem and the (shrunk) mutation that caused it."""
    notes = [n for n in getattr(found, "__notes__", []) if n.startswith("mutation")]
    text = found if isinstance(found, Finding) else f"{type(found).__name__}: {found}"
    return f"{text}; {notes[-1] if notes else 'no mutation recorded'}"


def _example_checker(s: Seed, tmp: Path, tally: Tally,
                     take: Callable[[], bytes]) -> Callable[[list[Op]], None]:
    """The body of one example of the long form: run it, check for output, count it."""
    def one(ops: list[Op]) -> None:
        folder = Path(tempfile.mkdtemp(dir=tmp))
        take()
        try:
            outcome = run_example(s, ops, folder)
            noise = take()
            if noise:
                raise Finding(f"output on stdout/stderr: {noise[:200]!r}")
        except Finding as found:
            found.add_note(f"mutation {ops!r}")
            raise
        tally.add(s.name, outcome)
    return one


def main(argv: list[str] | None = None) -> int:
    """Run the long form; print the summary; exit 1 when anything was found."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0, help="total time, minutes")
    parser.add_argument("--seed", type=int, default=0, help="first Hypothesis seed")
    parser.add_argument("--formats", default="", help="comma-separated seed names (default all)")
    parser.add_argument("--memory", type=float, default=4.0,
                        help="address-space limit of this process, GB (0: none)")
    args = parser.parse_args(argv)
    seeds = make_seeds()
    chosen = [seeds[n] for n in args.formats.split(",") if n] or list(seeds.values())
    if args.memory > 0:
        limit = int(args.memory * 1e9)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    start = time.monotonic()
    tally, findings = fuzz(chosen, args.minutes * 60.0, args.seed)
    print(f"{sum(tally.runs.values())} examples in {time.monotonic() - start:.0f} s "
          f"(seed {args.seed})")
    print("| format | examples | loaded | InputError | finding |")
    print("|---|---:|---:|---:|---:|")
    for s in chosen:
        got = tally.outcomes.get(s.name, Counter())
        print(f"| {s.name} | {tally.runs[s.name]} | {got['loaded']} | {got['InputError']} | "
              f"{got['finding']} |")
    for finding, times in Counter(findings).items():
        print(f"FINDING ({times} run{'s' if times > 1 else ''}) {finding}")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
