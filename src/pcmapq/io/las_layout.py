"""The layout of a LAS or LAZ file checked against the file's size before laspy and lazrs read
it: what a corrupt or truncated file would otherwise make them do (allocate tens of gigabytes
and end the process, or fail in a message naming a buffer) is refused here in one line.

A LAS file's header gives its point records' offset, length and count: the records must fit in
the file. A LAZ file's points are compressed in chunks (LASzip): its ``laszip encoded`` VLR
names the compressor and the items of a record; the compressed data starts with the offset of
its chunk table, whose first words are a version and the number of chunks (lazrs allocates a
table entry for each before reading any). Each chunk holds at least its first point
uncompressed, so the chunks cannot outnumber the records that fit between the data's start and
the table. A layered chunk (point formats 6 to 10) is its first point, a point count, the byte
size of each of its layers, then the layers (lazrs allocates each layer's size before reading
it): the sizes must fit before the chunk table (or the end of the file).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from pcmapq.core.errors import InputError

__all__ = ["LasLayout", "check_layout", "read_layout"]

#: The LAS header's fields read here: (offset, struct format).
_HEADER = struct.Struct("<4s21xB68xHIIBHI")  # signature, minor version, ..., legacy count
_COUNT_14 = (247, "<Q")  # LAS 1.4's 64-bit point count
#: A VLR's header, bytes, and the LASzip VLR's user id and record id.
VLR_HEADER = 54
LASZIP_USER, LASZIP_RECORD = b"laszip encoded", 22204
#: LASzip compressors: one stream, point-wise chunks, layered chunks.
POINTWISE, POINTWISE_CHUNKED, LAYERED_CHUNKED = 1, 2, 3
#: Layers of each LASzip item type of a layered chunk (point formats 6 to 10): Point14's nine,
#: RGB14's one, RGBNIR14's two (RGB and NIR), WavePacket14's one; Byte14 has one per byte.
LAYERS = {10: 9, 11: 1, 12: 2, 13: 1}
BYTE14 = 14


@dataclass(frozen=True)
class LasLayout:
    """What a LAS header declares: ``points``, each ``record`` bytes long, from ``offset``;
    ``compressed`` (LAZ); for LAZ, the LASzip ``compressor`` and its ``items`` (type, size)."""

    points: int
    record: int
    offset: int
    compressed: bool
    compressor: int = 0
    items: tuple[tuple[int, int], ...] = ()


def read_layout(path: Path, f: BinaryIO, size: int) -> LasLayout:
    """The layout the header of the LAS/LAZ file ``f`` (named ``path``, ``size`` bytes long)
    declares; InputError when it has no LAS header, more variable-length records than fit
    before its points, or its points are compressed without a LASzip VLR."""
    head = f.read(375)
    if len(head) < _HEADER.size or head[:4] != b"LASF":
        raise _unreadable(path, "no LAS header")
    _, minor, header_size, offset, vlrs, fmt, record, points = _HEADER.unpack_from(head)
    if minor >= 4 and len(head) >= _COUNT_14[0] + 8:
        points = struct.unpack_from(_COUNT_14[1], head, _COUNT_14[0])[0]
    room = max(min(offset, size) - header_size, 0)  # the records lie before the points
    if vlrs * VLR_HEADER > room:
        raise _unreadable(path, f"its header declares {vlrs:,} variable-length records in "
                          f"{room:,} bytes")
    compressed = bool(fmt & 0x80) and not fmt & 0x40  # laspy's test
    if not compressed:
        return LasLayout(points, record, offset, False)
    data = _laszip_vlr(f, header_size, vlrs)
    if data is None or len(data) < 34:
        raise _unreadable(path, "its points are compressed but it has no LASzip VLR")
    compressor = struct.unpack_from("<H", data)[0]
    count = struct.unpack_from("<H", data, 32)[0]
    items = tuple(struct.unpack_from("<HH", data, 34 + 6 * k) for k in range(count)
                  if 34 + 6 * k + 6 <= len(data))
    return LasLayout(points, record, offset, True, compressor, items)


def _laszip_vlr(f: BinaryIO, start: int, count: int) -> bytes | None:
    """The data of the LASzip VLR among the ``count`` VLRs from byte ``start``; None if absent."""
    at = start
    for _ in range(count):
        f.seek(at)
        head = f.read(VLR_HEADER)
        if len(head) < VLR_HEADER:
            return None
        user, record_id, length = struct.unpack_from("<16sHH", head, 2)
        if user.rstrip(b"\0") == LASZIP_USER and record_id == LASZIP_RECORD:
            return f.read(length)
        at += VLR_HEADER + length
    return None


def check_layout(path: Path) -> LasLayout:
    """The layout of the LAS/LAZ file ``path`` (:func:`read_layout`); InputError (one line)
    when its records do not fit in the file: a LAS file truncated, a LAZ file whose chunk table
    declares more chunks than fit, or whose layered chunks declare layers past its end."""
    size = path.stat().st_size
    with open(path, "rb") as f:
        layout = read_layout(path, f, size)
        if not layout.compressed:
            held = max(size - layout.offset, 0) // max(layout.record, 1)
            if held < layout.points:
                raise InputError(f"{path}: truncated: room for {held:,} of the "
                                 f"{layout.points:,} points its header declares")
            return layout
        if layout.points == 0 or layout.compressor not in (POINTWISE_CHUNKED, LAYERED_CHUNKED):
            return layout
        table = _chunk_table(path, f, layout, size)
        if layout.compressor == LAYERED_CHUNKED:
            _check_layers(path, f, layout, table or size)
    return layout


def _chunk_table(path: Path, f: BinaryIO, layout: LasLayout, size: int) -> int | None:
    """Where the chunk table starts (found as lazrs finds it: the offset at the data's start,
    else the file's last 8 bytes), None without one; InputError when it lies past the file's
    end, or declares more chunks than records fit between the data's start and the table."""
    start = layout.offset
    f.seek(start)
    word = f.read(8)
    table = struct.unpack("<q", word)[0] if len(word) == 8 else -1
    if table <= start and size >= 8:
        f.seek(size - 8)
        table = struct.unpack("<q", f.read(8))[0]
    if table <= start:
        return None
    if table + 8 > size:  # lazrs would read the points from a wrong place
        raise _unreadable(path, f"its chunk table lies at byte {table:,}, past its end "
                          f"({size:,} bytes): truncated or corrupt")
    f.seek(table + 4)
    chunks = struct.unpack("<I", f.read(4))[0]
    room = (table - start - 8) // max(_record(layout), 1)
    if chunks > room:
        raise _unreadable(path, f"its chunk table declares {chunks:,} chunks of compressed "
                          f"points, where {table - start - 8:,} bytes hold at most {room:,}")
    return table


def _check_layers(path: Path, f: BinaryIO, layout: LasLayout, end: int) -> None:
    """InputError when a layered chunk, walked from the data's start to ``end`` (the chunk
    table, or the end of the file), declares layers that go past ``end``."""
    layers = sum(size if kind == BYTE14 else LAYERS.get(kind, 0) for kind, size in layout.items)
    first = _record(layout)
    at, chunk = layout.offset + 8, 0
    while at < end:
        f.seek(at + first + 4)
        words = f.read(4 * layers)
        if len(words) < 4 * layers:
            return  # a truncated chunk: lazrs stops at its end
        sizes = struct.unpack(f"<{layers}I", words)
        length = first + 4 + 4 * layers + sum(sizes)
        if at + length > end:
            raise _unreadable(path, f"its compressed chunk {chunk + 1} declares layers of "
                              f"{sum(sizes):,} bytes, past the end of its points "
                              f"({end - at:,} bytes left)")
        at, chunk = at + length, chunk + 1


def _record(layout: LasLayout) -> int:
    """Bytes of one uncompressed record: its LASzip items' sizes (the header's record length
    when they are not known)."""
    return sum(size for _, size in layout.items) or layout.record


def _unreadable(path: Path, why: str) -> InputError:
    return InputError(f"{path}: not a readable LAS/LAZ file: {why}")
