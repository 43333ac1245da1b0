"""The vertex block of a binary PLY, read without Open3D and without loading the file whole.

The header is parsed here; the vertices are fixed-size records at a known offset, so they are
read in chunks (``np.fromfile`` with offset and count) or mapped (``np.memmap``). Only the
vertices' x, y, z are read, in the file's own frame and unit (metres for a map), with their
stored values: float32 coordinates come out exactly as Open3D's reader gives them.

ASCII PLY, and binary PLY whose vertices cannot be located without parsing every record (a list
property in the vertex element or in an element before it), are not handled here:
:func:`vertex_block` returns None and the caller reads them another way.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.words import plural

__all__ = ["VertexBlock", "check_size", "count_lines", "vertex_block"]

#: PLY scalar type names (both spellings) -> NumPy type codes, without byte order.
SCALARS = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
           "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
           "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
           "float64": "f8"}
#: The longest header read, bytes (comments included).
MAX_HEADER = 1 << 20
#: Vertices read at a time, by default.
CHUNK = 2_000_000


@dataclass(frozen=True)
class VertexBlock:
    """The vertices of a binary PLY: ``count`` records of ``dtype`` (structured, with its byte
    order) starting ``offset`` bytes into ``path``; coordinates in the fields x, y, z."""

    path: Path
    count: int
    offset: int
    dtype: np.dtype

    def read(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Vertices ``start`` to ``stop`` (default: the last) as (n, 3) float64 x, y, z."""
        stop = self.count if stop is None else min(stop, self.count)
        n = max(stop - start, 0)
        records = np.fromfile(self.path, dtype=self.dtype, count=n,
                              offset=self.offset + start * self.dtype.itemsize)
        if len(records) != n:  # the file changed since its size was checked
            raise InputError(f"{self.path}: truncated: vertex {start + len(records)} of "
                             f"{self.count} missing")
        out = np.empty((n, 3), dtype=np.float64)
        for axis, name in enumerate("xyz"):
            out[:, axis] = records[name]
        return out

    def chunks(self, size: int = CHUNK) -> Iterator[np.ndarray]:
        """All vertices, ``size`` at a time, as (n, 3) float64 x, y, z."""
        for start in range(0, self.count, size):
            yield self.read(start, start + size)

    def values(self, name: str) -> np.ndarray | None:
        """The scalar property ``name`` of every vertex, as a read-only array of its stored type
        mapped onto the file (nothing is read until used); None without that property."""
        if name not in (self.dtype.names or ()) or self.count == 0:
            return None
        records = np.memmap(self.path, dtype=self.dtype, mode="r", offset=self.offset,
                            shape=(self.count,))
        return records[name]

    def mapped(self) -> np.ndarray | None:
        """The vertices' x, y, z as a read-only (count, 3) array mapped onto the file (nothing is
        read until used), of the coordinates' own type; None unless x, y, z are one type and
        stored one after the other."""
        fields = [self.dtype.fields[name] for name in "xyz"]
        kind, first = fields[0][0], fields[0][1]
        if any(f[0] != kind or f[1] != first + axis * kind.itemsize
               for axis, f in enumerate(fields)) or self.count == 0:
            return None
        raw = np.memmap(self.path, dtype=np.uint8, mode="r", offset=self.offset,
                        shape=(self.count * self.dtype.itemsize,))
        return np.ndarray((self.count, 3), dtype=kind, buffer=raw, offset=first,
                          strides=(self.dtype.itemsize, kind.itemsize))


def vertex_block(path: Path) -> VertexBlock | None:
    """Parse the PLY header of ``path``: its vertex block, or None when the file is ASCII or
    its vertices cannot be located without reading every record (see the module's docstring).
    InputError for a header that is not PLY or is malformed, for missing x, y, z, and for a
    file shorter than its header promises (a truncated file)."""
    fmt, elements, offset = _header(path)
    if fmt == "ascii":
        return None
    order = "<" if fmt == "binary_little_endian" else ">"
    for name, count, props in elements:
        if any(kind.startswith("list") for _, kind in props):  # records vary in size
            return None
        try:
            dtype = np.dtype([(prop, order + kind) for prop, kind in props])
        except ValueError as exc:  # e.g. a property named twice
            raise InputError(f"{path}: bad PLY element {name}: {exc}") from None
        if name == "vertex":
            missing = [axis for axis in "xyz" if axis not in dtype.names]
            if missing:
                raise InputError(f"{path}: the PLY's vertices have no {', '.join(missing)}")
            size = path.stat().st_size
            need = offset + count * dtype.itemsize
            if size < need:
                raise InputError(f"{path}: truncated: header declares {count} "
                                 f"{plural(count, 'point')}, the file "
                                 f"holds {max(size - offset, 0) // dtype.itemsize}")
            return VertexBlock(path, count, offset, dtype)
        offset += count * dtype.itemsize
    raise InputError(f"{path}: no vertex element in the PLY header")


def check_size(path: Path) -> int:
    """The vertices the PLY ``path`` declares; InputError when it holds fewer records than its
    header declares: for a
    binary PLY, fewer bytes than its elements need (a list property counted at its smallest,
    an empty list), for an ASCII PLY fewer data lines than records. Open3D would pad the
    missing points with zeros."""
    fmt, elements, offset = _header(path)
    points = sum(count for name, count, _ in elements if name == "vertex")
    before = 0  # records (ASCII) or bytes (binary) of the elements before the vertices
    for name, count, props in elements:
        if name == "vertex":
            break
        before += count if fmt == "ascii" else count * _smallest_record(props)
    if fmt == "ascii":
        held = count_lines(path, offset)
        need = sum(count for _, count, _ in elements)
    else:
        held = path.stat().st_size - offset
        need = sum(count * _smallest_record(props) for _, count, props in elements)
    if held < need:
        vertex = [props for name, _, props in elements if name == "vertex"]
        per_point = 1 if fmt == "ascii" or not vertex else _smallest_record(vertex[0])
        present = min(max(held - before, 0) // per_point, points)
        raise InputError(f"{path}: truncated: header declares {points} "
                         f"{plural(points, 'point')}, "
                         f"the file holds {present}")
    return points


def _header(path: Path) -> tuple[str, list[tuple[str, int, list]], int]:
    """The format and elements of a PLY's header (see :func:`_parse`) and the offset of its
    data, bytes."""
    with path.open("rb") as f:
        head = f.read(MAX_HEADER)
    if not head.startswith(b"ply"):
        raise InputError(f"{path}: not a PLY file")
    end = head.find(b"end_header")
    newline = head.find(b"\n", end) if end >= 0 else -1
    if newline < 0:
        raise InputError(f"{path}: PLY header without end_header")
    fmt, elements = _parse(path, head[:end].decode("ascii", errors="replace").splitlines())
    return fmt, elements, newline + 1


def _smallest_record(props: list[tuple[str, str]]) -> int:
    """The fewest bytes a binary record of these properties takes (a list: its count)."""
    return sum(np.dtype(kind.removeprefix("list")).itemsize for _, kind in props)


def count_lines(path: Path, offset: int, chunk: int = 1 << 24) -> int:
    """The lines of ``path`` from byte ``offset`` on (the last one counted without its newline
    too), read ``chunk`` bytes at a time. Blank lines count too, so none makes a file short."""
    lines, last = 0, b"\n"
    with path.open("rb") as f:
        f.seek(offset)
        while block := f.read(chunk):
            lines += block.count(b"\n")
            last = block[-1:]
    return lines + (last != b"\n")


def _parse(path: Path, lines: list[str]) -> tuple[str, list[tuple[str, int, list]]]:
    """The format and the elements (name, count, [(property, type code)]) of a PLY header's
    lines (without end_header); a list property's type is ``list`` and its count's code."""
    fmt, elements = "", []
    for number, line in enumerate(lines[1:], start=2):
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        try:
            if words[0] == "format":
                fmt = words[1]
                if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
                    raise ValueError(f"unknown format {fmt}")
            elif words[0] == "element":
                count = int(words[2])
                if count < 0:
                    raise ValueError(f"negative count {count}")
                elements.append((words[1], count, []))
            elif words[0] == "property" and elements:
                if words[1] == "list":  # "list" and the type of its count
                    if words[2] not in SCALARS:
                        raise ValueError(f"unknown type {words[2]}")
                    elements[-1][2].append((words[4], "list" + SCALARS[words[2]]))
                elif words[1] in SCALARS:
                    elements[-1][2].append((words[2], SCALARS[words[1]]))
                else:
                    raise ValueError(f"unknown type {words[1]}")
            else:
                raise ValueError(f"unexpected '{words[0]}'")
        except (IndexError, ValueError) as exc:
            raise InputError(f"{path}: bad PLY header line {number} ({line.strip()[:60]!r}): "
                             f"{exc}") from None
    if not fmt:
        raise InputError(f"{path}: PLY header without a format line")
    return fmt, elements
