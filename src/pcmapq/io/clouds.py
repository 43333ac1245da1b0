"""Point-cloud maps: PLY, PCD, text (.xyz, .txt), NumPy .npy and KITTI .bin.

Points are (N, 3) float64 metres in the file's own frame. Rows with a non-finite coordinate are
dropped. A cloud whose z is constant (to 1e-6 m) is 2D: its z is set to 0.

Binary PLY is read by :mod:`pcmapq.io.ply` (the values Open3D's reader gives, without its
copies); a large one (more than ``MAP_POINTS`` vertices, 3D, every coordinate finite) is not
read at all here but mapped: its points are a read-only array onto the file, in the file's own
coordinate type, that the steps using them read chunk by chunk. Binary PCD is read by
:mod:`pcmapq.io.pcd`, its coordinates as stored (float ones as Open3D's reader gives them; it
reads double ones as zeros), an ASCII PCD by it too. ASCII PLY and compressed PCD go through
Open3D.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from tokenize import TokenError

import numpy as np
from numpy.lib import format as npy

from pcmapq.core import memory
from pcmapq.core.errors import InputError
from pcmapq.core.memory import check_points
from pcmapq.io import pcd, ply
from pcmapq.io.ply import CHUNK, VertexBlock, vertex_block
from pcmapq.io.stderr import stderr_captured
from pcmapq.io.survey import read_e57, read_las
from pcmapq.io.writers import SCAN, one_line

#: A PCD's coordinate fields (PCL's names).
XYZ = ("x", "y", "z")

#: z range (metres) above which a cloud counts as 3D.
FLAT_TOLERANCE = 1e-6
#: A binary PLY with more vertices than this is mapped, not read (see the module's docstring).
MAP_POINTS = CHUNK


#: Side of the cells of :class:`SeenCells`, metres (the map's frame).
SEEN_CELL = 0.05


@dataclass(frozen=True)
class SeenCells:
    """The area a map's scans saw, as cells of a lattice of :data:`SEEN_CELL` squares in the
    map's own frame (:mod:`pcmapq.raster.seen` fills and draws it): ``cells`` (rows, cols)
    bool, whose row r and column c is the lattice cell (``corner[0] + c``, ``corner[1] + r``),
    which covers ``[i, i + 1) x [j, j + 1)`` cells from the frame's origin (x right, y up)."""

    cells: np.ndarray
    corner: tuple[int, int]


@dataclass(frozen=True)
class PointMap:
    """A point-cloud map.

    path: the file given.
    points: (N, 3) float64 metres, every row finite; z = 0 for 2D clouds. For a large binary PLY
        (see the module's docstring) a read-only (N, 3) float32 or float64 array mapped onto the
        file: read it in chunks (``pcmapq.io.ply.CHUNK`` rows), never convert it whole.
    is_3d: False when z is constant (a 2D cloud).
    seen: for a map made of scans with known poses, the area its scans saw (the union of
        their views, see :mod:`pcmapq.raster.seen`); None otherwise.
    scan: for a map built from scans (``pcmapq map``), each point's scan (N,), the mean index
        of the scans it came from (:mod:`pcmapq.mapping.scan_map`); None otherwise.
    """

    path: Path
    points: np.ndarray
    is_3d: bool
    kind: str = "cloud"
    seen: SeenCells | None = None
    scan: np.ndarray | None = None

    @classmethod
    def of_scans(cls, path: Path, points: np.ndarray, scan: np.ndarray | None = None,
                 seen: SeenCells | None = None) -> PointMap:
        """A map made of the scans at ``path`` (kind ``scans``): its points (N, 3, metres),
        3D unless they are flat, with each point's scan and the area its scans saw when
        known."""
        return cls(path, points, not flat(points), kind="scans", seen=seen, scan=scan)


def flat(points: np.ndarray) -> bool:
    """Whether points (N, 3) are a 2D cloud: z constant within :data:`FLAT_TOLERANCE` (a
    laser scanner's scans, a 2D map)."""
    return not (len(points) and float(np.ptp(points[:, 2])) > FLAT_TOLERANCE)


def load_cloud(path: Path, memory_limit: int | None = None) -> PointMap:
    """Load a point cloud, choosing the reader by extension (LAS, LAZ and E57:
    :mod:`pcmapq.io.survey`); a PLY, PCD, .npy, KITTI .bin, LAS or E57 whose
    header (or size) declares more points than ``memory_limit`` bytes hold (None: the default
    limit, see :mod:`pcmapq.core.memory`) is refused unread."""
    readers: dict[str, Callable[[Path], np.ndarray]] = {
        ".ply": lambda p: read_open3d(p, memory_limit),
        ".pcd": lambda p: read_pcd(p, memory_limit), ".xyz": read_text, ".txt": read_text,
        ".npy": lambda p: read_npy(p, memory_limit),
        ".bin": lambda p: read_kitti_bin(p, memory_limit),
        ".las": lambda p: read_las(p, memory_limit), ".laz": lambda p: read_las(p, memory_limit),
        ".e57": lambda p: read_e57(p, memory_limit),
    }
    scan = None
    try:
        block = vertex_block(path) if path.suffix.lower() == ".ply" else None
        if block is not None:
            scan = _scan(path, block.values(SCAN))
            mapped = _mapped_3d(block) if block.count > MAP_POINTS else None
            if mapped is not None:
                return PointMap(path, mapped, True, scan=scan)
            check_points(path, block.count, memory_limit)
            points = np.empty((block.count, 3), dtype=np.float64)
            for start in range(0, block.count, CHUNK):
                points[start:start + CHUNK] = block.read(start, start + CHUNK)
        else:
            points = with_z(path, readers[path.suffix.lower()](path))
            if path.suffix.lower() == ".pcd":
                scan = _scan(path, pcd_scan(path))
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {one_line(exc)}") from None
    if not np.isfinite(points).all():
        finite = np.isfinite(points).all(axis=1)
        points, scan = points[finite], None if scan is None else scan[finite]
    if len(points) == 0:
        raise InputError(f"{path}: no points")
    is_3d = not flat(points)
    if not is_3d:
        points[:, 2] = 0.0
    return PointMap(path, points, is_3d, scan=None if scan is None else np.array(scan))


def pcd_scan(path: Path) -> np.ndarray | None:
    """The ``scan`` field of a binary PCD (each point's, as stored); None without one, or for
    an ASCII or compressed PCD."""
    header = pcd.read_header(path)
    if SCAN not in header.fields:
        return None
    table = pcd.read_fields(path, [SCAN], header)
    return None if table is None else table[SCAN]


def _scan(path: Path, values: np.ndarray | None) -> np.ndarray | None:
    """A cloud's ``scan`` values (each point's scan, :mod:`pcmapq.mapping.scan_map`) when
    every one is a finite number of at least 0, else None, with a warning naming the file for
    values that are not (the map's regions are then tiles)."""
    if values is None:
        return None
    ok = len(values) > 0 and np.issubdtype(values.dtype, np.number)
    for start in range(0, len(values), CHUNK) if ok else ():
        chunk = values[start:start + CHUNK]
        if not (np.isfinite(chunk).all() and chunk.min() >= 0):
            ok = False
            break
    if not ok:
        warnings.warn(f"{path}: its '{SCAN}' values are not all numbers of at least 0: they "
                      "are not read as the scans its points came from", stacklevel=2)
        return None
    return values


def _mapped_3d(block: VertexBlock) -> np.ndarray | None:
    """The block's x, y, z mapped onto the file (:meth:`VertexBlock.mapped`) when every
    coordinate is finite and z is not constant; else None (the caller reads it). Reads the
    file once, in chunks."""
    mapped = block.mapped()
    if mapped is None:
        return None
    z_lo, z_hi = np.inf, -np.inf
    for start in range(0, len(mapped), CHUNK):
        chunk = mapped[start:start + CHUNK]
        if not np.isfinite(chunk).all():
            return None
        z_lo, z_hi = min(z_lo, float(chunk[:, 2].min())), max(z_hi, float(chunk[:, 2].max()))
    return mapped if z_hi - z_lo > FLAT_TOLERANCE else None


def with_z(path: Path, table: np.ndarray) -> np.ndarray:
    """(N, 2) or (N, 3+) numbers -> (N, 3) float64 x, y, z (z = 0 when absent); a fresh array."""
    if table.ndim != 2 or (table.shape[1] < 2 and table.size > 0):
        raise InputError(f"{path}: expected N x 2 or N x 3 numbers, got shape {table.shape}")
    if not (np.issubdtype(table.dtype, np.integer) or np.issubdtype(table.dtype, np.floating)):
        raise InputError(f"{path}: expected numbers, got {table.dtype} values")
    out = np.zeros((len(table), 3), dtype=np.float64)
    cols = min(table.shape[1], 3)
    with np.errstate(invalid="ignore"):  # a float32 signalling NaN (the row is dropped later)
        out[:, :cols] = table[:, :cols]
    return out


def read_pcd(path: Path, memory_limit: int | None = None) -> np.ndarray:
    """A PCD's x, y, z (N, 3) (fields ``x y z``, or ``X Y Z``: :func:`pcmapq.io.pcd.
    coordinate_names`), once its header is checked against the data the file holds and the
    points it declares against ``memory_limit`` bytes: a binary one's as stored, read by
    :func:`pcmapq.io.pcd.read_fields`, an ASCII one's by :func:`pcmapq.io.pcd.read_ascii`, a
    compressed one's by Open3D (:func:`read_open3d`)."""
    header = pcd.check_size(path)
    check_points(path, header.points, memory_limit)
    names = pcd.coordinate_names(path, header)
    if header.data == "ascii":
        return pcd.read_ascii(path, header, names)
    table = pcd.read_fields(path, names, header)
    if table is None:
        with pcd.open3d_readable(path, header, names) as readable:
            return read_open3d(readable, memory_limit, shown=path)
    return np.column_stack([table[axis] for axis in names])


def read_open3d(path: Path, memory_limit: int | None = None,
                shown: Path | None = None) -> np.ndarray:
    """PLY or PCD via Open3D, once its header is checked against the data the file holds
    (InputError for a truncated file). Open3D reports unreadable files by returning no
    points, and a PLY that RPly cannot parse by RPly's message on stderr (the points after it
    zeros): that message, captured, is the InputError's. The points declared are checked
    against ``memory_limit`` bytes first (:func:`check_points`). ``shown``: the path messages
    name (a copy of it is read), default ``path``."""
    import open3d as o3d  # heavy: loaded when a PLY or PCD is read

    shown = path if shown is None else shown
    if path.suffix.lower() == ".ply":  # Open3D pads a short file with zeros, printing RPly errors
        check_points(shown, ply.check_size(path), memory_limit)
    else:
        check_points(shown, pcd.check_size(path).points, memory_limit)
    with (o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error),
          stderr_captured() as printed):
        cloud = o3d.io.read_point_cloud(str(path))
    rply = [line[6:] for line in printed if line.startswith("RPly: ")]
    if rply:  # Open3D gives the points read before the error, padded with zeros
        raise InputError(f"{shown}: corrupt PLY: {rply[0].strip()}")
    if printed:  # not RPly's: passed on
        print("\n".join(printed), file=sys.stderr)
    if not cloud.has_points():
        raise InputError(f"{shown}: no points (empty or unreadable)")
    return np.asarray(cloud.points, dtype=np.float64)


def read_text(path: Path) -> np.ndarray:
    """Whitespace- or comma-separated columns x, y[, z, ...]; ``#`` starts a comment."""
    try:
        with path.open(encoding="utf-8") as f, warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
            lines = (line.replace(",", " ") for line in f)
            return np.loadtxt(lines, dtype=np.float64, comments="#", ndmin=2)
    except ValueError as exc:  # includes UnicodeDecodeError
        raise InputError(f"{path}: not a table of numbers: {one_line(exc)}") from None


def read_npy(path: Path, memory_limit: int | None = None) -> np.ndarray:
    """A NumPy array N x 2 or N x 3+ of numbers (no pickles)."""
    check_npy(path, memory_limit)
    try:
        return np.load(path, allow_pickle=False)
    except (ValueError, EOFError) as exc:
        raise InputError(f"{path}: cannot be read as .npy: {one_line(exc)}") from None


def check_npy(path: Path, memory_limit: int | None = None) -> None:
    """InputError, before anything is allocated, when the header of the .npy ``path`` declares
    more bytes than the file holds (truncated, or an absurd shape) or an array the memory guard
    (:mod:`pcmapq.core.memory`; ``memory_limit`` bytes, None: the default) refuses as a cloud."""
    with path.open("rb") as f:
        try:
            version = npy.read_magic(f)
            read = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
            shape, _, dtype = read(f, max_header_size=10_000)
        except (ValueError, TypeError, SyntaxError, TokenError) as exc:  # a garbled header
            raise InputError(f"{path}: not a .npy file: {one_line(exc)}") from None
        offset = f.tell()
    rows = shape[0] if shape else 1
    declared = int(np.prod(shape, dtype=object)) * dtype.itemsize
    held = path.stat().st_size - offset
    if declared > held:
        raise InputError(f"{path}: truncated or corrupt: header declares shape "
                         f"{tuple(shape)} ({declared} bytes), the file holds {held} bytes")
    memory.guard(memory.needed_bytes(0, 0, 0.0, int(rows)), memory_limit, str(path))


def read_kitti_bin(path: Path, memory_limit: int | None = None) -> np.ndarray:
    """KITTI Velodyne scan: little-endian float32 records x, y, z, reflectance (their count
    checked against ``memory_limit`` bytes, None: the default limit)."""
    size = path.stat().st_size
    if size % 16:
        raise InputError(f"{path}: size {size} bytes is not a multiple of 16 "
                         "(expected float32 x, y, z, reflectance records)")
    check_points(path, size // 16, memory_limit)
    return np.fromfile(path, dtype="<f4").reshape(-1, 4)[:, :3]

