"""The header of a PCD file, checked against the data the file holds before Open3D reads it.

Open3D pads a PCD shorter than its header declares with zeros (points at the origin); here a
file with fewer points than its ``POINTS`` (or ``WIDTH`` x ``HEIGHT``) is refused instead:
``DATA ascii`` counts its data lines, ``DATA binary`` its bytes (points x record size, the
record being the sum of ``SIZE`` x ``COUNT``), ``DATA binary_compressed`` the compressed block
its size word announces and the uncompressed size against the points declared.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

from pcmapq.core.errors import InputError
from pcmapq.io.ply import count_lines

__all__ = ["PcdHeader", "check_size", "read_header"]

#: The longest header read, bytes (comments included).
MAX_HEADER = 1 << 20


@dataclass(frozen=True)
class PcdHeader:
    """What a PCD header declares: ``points``, the bytes of one point's ``record``, the
    ``data`` kind (ascii, binary, binary_compressed) and the ``offset`` of the data, bytes."""

    points: int
    record: int
    data: str
    offset: int


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
    return PcdHeader(points, record, data, offset)


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
        raise InputError(f"{path}: truncated: header declares {header.points} points, "
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
