"""File formats other tools read: point clouds with a scalar field and colours (binary PLY, as
CloudCompare, Open3D and MeshLab read it; binary PCD, as PCL and Open3D read it; LAS and LAZ,
the scalar field an extra dimension, as CloudCompare and PDAL read them) and transform matrices
as plain text (``np.loadtxt``, CloudCompare's "Apply transformation" file).

Clouds are written from chunks of records, so a cloud of any size needs one chunk of memory;
every file is written whole or not at all (:func:`pcmapq.io.writers.atomic_file`).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.words import plural
from pcmapq.io.writers import OutputSet, atomic_file

#: The scalar field of a distance cloud: metres. CloudCompare reads a PLY property named
#: ``scalar_<name>`` as the scalar field ``<name>``.
DISTANCE_FIELD = "scalar_distance_m"
#: Extensions :func:`write_records` writes.
CLOUD_SUFFIXES = (".ply", ".pcd", ".las", ".laz")
#: LAS coordinates are integers of this many metres (a millimetre).
LAS_SCALE = 0.001

_PLY_TYPES = {"f4": "float", "u1": "uchar"}


def record_dtype(scalar: str | None = None, colour: bool = False) -> np.dtype:
    """Little-endian records: float32 x, y, z (metres), then float32 ``scalar`` and uchar red,
    green, blue when asked."""
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if scalar is not None:
        fields.append((scalar, "<f4"))
    if colour:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    return np.dtype(fields)


def records(xyz: np.ndarray, dtype: np.dtype, scalar: np.ndarray | None = None,
            rgb: np.ndarray | None = None) -> np.ndarray:
    """Points (n, 3) metres, with a scalar (n,) and colours (n, 3) uint8 when ``dtype`` has
    them, as records of ``dtype`` (:func:`record_dtype`)."""
    out = np.empty(len(xyz), dtype=dtype)
    for axis, name in enumerate("xyz"):
        out[name] = xyz[:, axis]
    if scalar is not None:
        out[dtype.names[3]] = scalar
    if rgb is not None:
        for axis, name in enumerate(("red", "green", "blue")):
            out[name] = rgb[:, axis]
    return out


def write_records(path: Path, count: int, chunks: Iterable[np.ndarray], dtype: np.dtype,
                  comment: str = "", outputs: OutputSet | None = None) -> None:
    """Write ``count`` records of ``dtype`` (:func:`record_dtype`), given as chunks, as a binary
    PLY (every field a vertex property), a binary PCD (every field but colours) or LAS / LAZ (a
    scalar an extra dimension named without its ``scalar_`` prefix, colours as RGB), by ``path``'s
    extension; ``comment`` (one line) goes into the header; with ``outputs``, the file appears
    when that set is committed."""
    suffix = path.suffix.lower()
    if suffix not in CLOUD_SUFFIXES:
        raise InputError(f"{path}: a cloud is written as .ply, .pcd, .las or .laz")
    if suffix in (".las", ".laz"):
        with atomic_file(path, outputs) as f:
            written = _write_las(f, suffix == ".laz", chunks, dtype)
        if written != count:
            raise InputError(f"{path}: {written} {plural(written, 'point')} written, {count} "
                             "announced")
        return
    if suffix == ".pcd" and "red" in dtype.names:
        raise InputError(f"{path}: a cloud with colours is written as .ply")
    header = (_ply_header(count, dtype, comment) if suffix == ".ply" else
              _pcd_header(count, dtype))
    written = 0
    with atomic_file(path, outputs) as f:
        f.write(header.encode("ascii"))
        for chunk in chunks:
            f.write(np.ascontiguousarray(chunk, dtype=dtype).tobytes())
            written += len(chunk)
        if written != count:
            raise InputError(f"{path}: {written} {plural(written, 'point')} written, {count} "
                             "announced")


def write_matrix(path: Path, matrix: np.ndarray, outputs: OutputSet | None = None) -> None:
    """A 3x3 or 4x4 homogeneous transform as plain text: one row a line, numbers separated by
    one space, shortest exact form (reading it back gives the same floats); with ``outputs``,
    the file appears when that set is committed."""
    rows = np.asarray(matrix, dtype=np.float64)
    with atomic_file(path, outputs) as f:
        f.write("".join(" ".join(repr(float(v) + 0.0) for v in row) + "\n"
                        for row in rows).encode("ascii"))


def _ply_header(count: int, dtype: np.dtype, comment: str) -> str:
    """The header of a binary little-endian PLY of ``count`` vertices of ``dtype``."""
    lines = ["ply", "format binary_little_endian 1.0"]
    lines += [f"comment {comment}"] if comment else []
    lines.append(f"element vertex {count}")
    lines += [f"property {_PLY_TYPES[dtype[name].str[1:]]} {name}" for name in dtype.names]
    return "\n".join([*lines, "end_header"]) + "\n"


def _pcd_header(count: int, dtype: np.dtype) -> str:
    """The header of a binary PCD (v0.7) of ``count`` points of ``dtype``'s float32 fields."""
    n = len(dtype.names)
    return ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
            f"FIELDS {' '.join(dtype.names)}\nSIZE {' '.join(['4'] * n)}\n"
            f"TYPE {' '.join(['F'] * n)}\nCOUNT {' '.join(['1'] * n)}\n"
            f"WIDTH {count}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {count}\n"
            "DATA binary\n")


def _write_las(f, compress: bool, chunks: Iterable[np.ndarray], dtype: np.dtype) -> int:
    """Records as LAS 1.4 (point format 6, or 7 with colours) into the open binary file ``f``,
    chunk by chunk; the count written."""
    import laspy

    colour = "red" in dtype.names
    scalar = [n for n in dtype.names if n not in ("x", "y", "z", "red", "green", "blue")]
    header = laspy.LasHeader(point_format=7 if colour else 6, version="1.4")
    header.scales = np.full(3, LAS_SCALE)
    header.offsets = np.zeros(3)
    for name in scalar:
        header.add_extra_dim(laspy.ExtraBytesParams(name=name.removeprefix("scalar_"),
                                                    type=np.float32))
    written = 0
    with laspy.open(f, mode="w", header=header, do_compress=compress, closefd=False) as out:
        for chunk in chunks:
            points = laspy.ScaleAwarePointRecord.zeros(len(chunk), header=header)
            points.x, points.y, points.z = chunk["x"], chunk["y"], chunk["z"]
            for name in scalar:
                points[name.removeprefix("scalar_")] = chunk[name]
            if colour:  # LAS colours are 16-bit
                for name in ("red", "green", "blue"):
                    points[name] = chunk[name].astype(np.uint16) * 257
            out.write_points(points)
            written += len(chunk)
    return written
