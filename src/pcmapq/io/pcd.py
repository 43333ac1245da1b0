"""The header of a PCD file, checked against the data the file holds before Open3D reads it.

Open3D pads a PCD shorter than its header declares with zeros (points at the origin); here a
file with fewer points than its ``POINTS`` (or ``WIDTH`` x ``HEIGHT``) is refused instead:
``DATA ascii`` counts its data lines, ``DATA binary`` its bytes (points x record size, the
record being the sum of ``SIZE`` x ``COUNT``), ``DATA binary_compressed`` the compressed block
its size word announces and the uncompressed size against the points declared.

The fields of a ``DATA binary`` file, fixed-size records at a known offset, are read here too
(:func:`read_fields`), with their stored values, without importing Open3D (slow to load): the values
Open3D's tensor reader gives, which its legacy reader gives too but for double coordinates
(zeros). So are the coordinates of a ``DATA ascii`` file (:func:`read_ascii`), whose values
may be separated by commas as well as spaces and tabs. Compressed files are left to Open3D.

The coordinates are the fields ``x``, ``y`` and ``z`` (PCL's names), else ``X``, ``Y`` and
``Z`` (PDAL's): :func:`coordinate_names`. Open3D reads only the former: a file of the latter
that it reads (compressed) is given to it as a copy whose ``FIELDS`` line names them in small
letters (:func:`open3d_readable`).
"""

from __future__ import annotations

import itertools
import shutil
import struct
import tempfile
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.words import plural
from pcmapq.io.ply import count_lines
from pcmapq.io.writers import one_line

__all__ = ["PcdField", "PcdHeader", "check_size", "coordinate_names", "open3d_readable",
           "read_ascii", "read_fields", "read_header"]

#: The longest header read, bytes (comments included).
MAX_HEADER = 1 << 20


#: The NumPy kinds of PCD's TYPE letters, with the SIZEs each is read in.
KINDS = {"F": ("f", (4, 8)), "I": ("i", (1, 2, 4, 8)), "U": ("u", (1, 2, 4, 8))}


@dataclass(frozen=True)
class PcdField:
    """One field of a PCD record: its NumPy ``type`` (little-endian, as PCD stores it; None
    when NumPy does not hold its TYPE and SIZE, or it has several values, COUNT > 1), its
    ``offset`` in the record, bytes, and the ``column`` of its first value on an ASCII line."""

    type: str | None
    offset: int
    column: int = field(default=0, compare=False)


@dataclass(frozen=True)
class PcdHeader:
    """What a PCD header declares: ``points``, the bytes of one point's ``record``, the
    ``data`` kind (ascii, binary, binary_compressed), the ``offset`` of the data, bytes, and
    the ``fields`` of a record by name (the first of a repeated name)."""

    points: int
    record: int
    data: str
    offset: int
    fields: dict[str, PcdField] = field(default_factory=dict)


def read_header(path: Path) -> PcdHeader:
    """Parse the header of the PCD ``path``; InputError (one line) when it is malformed."""
    with path.open("rb") as f:
        head = f.read(MAX_HEADER)
    fields: dict[str, list[str]] = {}
    offset = 0
    for raw in head.split(b"\n"):
        offset += len(raw) + 1
        words = raw.decode("ascii", errors="replace").split()
        if not words or words[0].startswith("#"):
            continue
        fields[words[0].upper()] = words[1:]
        if words[0].upper() == "DATA":
            break
    else:
        raise InputError(f"{path}: not a PCD file (no DATA line in its header)")
    try:
        sizes = [int(v) for v in fields["SIZE"]]
        counts = [int(v) for v in fields.get("COUNT", ["1"] * len(sizes))]
        if "POINTS" in fields:
            points = int(fields["POINTS"][0])
        else:
            points = int(fields["WIDTH"][0]) * int(fields["HEIGHT"][0])
        data = fields["DATA"][0].lower()
    except (KeyError, IndexError, ValueError) as exc:
        raise InputError(f"{path}: bad PCD header ({type(exc).__name__}: {exc})") from None
    if points < 0 or len(counts) != len(sizes) or min(sizes + counts, default=0) < 0:
        raise InputError(f"{path}: bad PCD header (negative or mismatched SIZE, COUNT, POINTS)")
    if data not in ("ascii", "binary", "binary_compressed"):
        raise InputError(f"{path}: unknown PCD DATA kind {data!r}")
    record = sum(s * c for s, c in zip(sizes, counts, strict=True))
    return PcdHeader(points, record, data, offset,
                     _fields(fields.get("FIELDS", []), fields.get("TYPE", []), sizes, counts))


def _fields(names: list[str], types: list[str], sizes: list[int],
            counts: list[int]) -> dict[str, PcdField]:
    """The fields of a record by name (none when FIELDS, TYPE and SIZE disagree in length)."""
    if not len(names) == len(types) == len(sizes):
        return {}
    out: dict[str, PcdField] = {}
    offset = column = 0
    for name, letter, size, count in zip(names, types, sizes, counts, strict=True):
        kind, held = KINDS.get(letter.upper(), ("", ()))
        numpy_type = f"<{kind}{size}" if size in held and count == 1 else None
        out.setdefault(name, PcdField(numpy_type, offset, column))
        offset += size * count
        column += count
    return out


#: The coordinates' field names: PCL's, then PDAL's.
COORDINATES = (("x", "y", "z"), ("X", "Y", "Z"))


def coordinate_names(path: Path, header: PcdHeader) -> tuple[str, str, str]:
    """The names of the fields that hold x, y and z (:data:`COORDINATES`); InputError, naming
    the fields the file has, when it has neither set."""
    for names in COORDINATES:
        if all(n in header.fields for n in names):
            return names
    if not header.fields:
        raise InputError(f"{path}: bad PCD header: FIELDS, SIZE and TYPE list different "
                         "numbers of fields")
    raise InputError(f"{path}: no x, y, z fields; its fields: {', '.join(header.fields)}")


def read_ascii(path: Path, header: PcdHeader, names: Sequence[str]) -> np.ndarray:
    """The fields ``names`` of the ``DATA ascii`` PCD ``path``, (points, len(names)) float64:
    the first ``header.points`` lines of its data (blank lines skipped, as PCL does), values
    separated by spaces, tabs or commas; InputError when a line lacks a value or holds one
    that is not a number, or the lines are fewer than the points."""
    if header.points == 0:
        return np.empty((0, len(names)))
    columns = [header.fields[n].column for n in names]
    try:
        with path.open("rb") as f, warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
            f.seek(header.offset)
            lines = (line.decode("ascii", errors="replace").replace(",", " ") for line in f
                     if line.strip())  # PCL skips blank lines
            table = np.loadtxt(itertools.islice(lines, header.points), dtype=np.float64,
                               comments=None, usecols=columns, ndmin=2)
    except ValueError as exc:
        raise InputError(f"{path}: bad ASCII PCD data: {one_line(exc)}") from None
    if len(table) < header.points:
        raise InputError(f"{path}: truncated: header declares {header.points} points, the "
                         f"file holds {len(table)}")
    return table


@contextmanager
def open3d_readable(path: Path, header: PcdHeader, names: Sequence[str]) -> Iterator[Path]:
    """``path`` itself when its coordinates are named ``x y z``; else a temporary copy whose
    ``FIELDS`` line names them so (the file itself is not changed), removed after the block."""
    if tuple(names) == COORDINATES[0]:
        yield path
        return
    with path.open("rb") as f:
        head = f.read(header.offset)
        lines = head.split(b"\n")
        for k, line in enumerate(lines):
            words = line.split()
            if words and words[0].upper() == b"FIELDS":
                renamed = {n.encode(): n.lower().encode() for n in names}
                lines[k] = b" ".join(renamed.get(w, w) for w in words)
                break
        with tempfile.TemporaryDirectory() as folder:
            copy = Path(folder) / "cloud.pcd"
            with copy.open("wb") as out:
                out.write(b"\n".join(lines))
                shutil.copyfileobj(f, out)
            yield copy


def read_fields(path: Path, names: Sequence[str],
                header: PcdHeader | None = None) -> dict[str, np.ndarray] | None:
    """The fields ``names`` of the ``DATA binary`` PCD ``path`` that it has, one array each of
    its points, of the type stored; None when its data is ASCII or compressed, or one of those
    fields has a type NumPy does not hold or several values (Open3D reads those files).
    ``header``: :func:`check_size`'s of the file, when already read (else read here, and
    InputError for a truncated file)."""
    header = check_size(path) if header is None else header
    present = [n for n in names if n in header.fields]
    if header.data != "binary" or any(header.fields[n].type is None for n in present):
        return None
    if not present:
        return {}
    layout = np.dtype({"names": present, "formats": [header.fields[n].type for n in present],
                       "offsets": [header.fields[n].offset for n in present],
                       "itemsize": header.record})
    with path.open("rb") as f:
        table = np.fromfile(f, dtype=layout, count=header.points, offset=header.offset)
    return {n: table[n] for n in present}


def check_size(path: Path) -> PcdHeader:
    """The header of the PCD ``path``; InputError when the file holds fewer points than it
    declares."""
    header = read_header(path)
    size = path.stat().st_size - header.offset
    if header.data == "ascii":
        held = count_lines(path, header.offset)
    elif header.data == "binary":
        held = size // header.record if header.record else header.points
    else:
        held = _compressed_points(path, header, size)
    if held < header.points:
        raise InputError(f"{path}: truncated: header declares {header.points} "
                         f"{plural(header.points, 'point')}, "
                         f"the file holds {held}")
    return header


def _compressed_points(path: Path, header: PcdHeader, size: int) -> int:
    """The points a ``binary_compressed`` block holds: all of them when its compressed bytes are
    present and its uncompressed size is the points declared x the record; else none."""
    with path.open("rb") as f:
        f.seek(header.offset)
        words = f.read(8)
    if len(words) < 8:
        return 0
    compressed, uncompressed = struct.unpack("<II", words)
    if size < 8 + compressed or uncompressed != header.points * header.record:
        return 0
    return header.points
