"""Survey clouds: LAS and LAZ (laspy with the lazrs backend) and E57 (pye57, libE57Format),
as CloudCompare reads them. Points (N, 3) float64 metres in the file's frame: LAS's scaled
coordinates; an E57's scans each placed by its pose, in the file's common frame. The points a
header declares are checked against the memory limit before any is read; a LAS file is read
in chunks."""

from __future__ import annotations

import logging
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.memory import check_points
from pcmapq.core.words import plural
from pcmapq.io.las_layout import check_layout
from pcmapq.io.stderr import stderr_captured
from pcmapq.io.writers import one_line

#: Points read from a LAS file at a time (a record is up to 64 kB: a few MB a chunk).
LAS_CHUNK = 100_000


def read_las(path: Path, memory_limit: int | None = None) -> np.ndarray:
    """A LAS or LAZ file's points, metres (its header's scales and offsets applied). Its layout
    is checked against its size first (:mod:`pcmapq.io.las_layout`); the decoder's failures,
    a Rust panic among them, are one InputError line."""
    import laspy


    xyz = laspy.DecompressionSelection.XY_RETURNS_CHANNEL | laspy.DecompressionSelection.Z
    layout = check_layout(path)
    check_points(path, layout.points, memory_limit)
    _quiet("laspy")
    done = count = 0
    try:
        # Neither the extended VLRs (a corrupt count makes laspy parse the file as thousands
        # of them) nor, in a layered LAZ, other layers than x, y, z are read.
        with laspy.open(path, laz_backend=laspy.LazBackend.Lazrs, read_evlrs=False,
                        decompression_selection=xyz) as reader:
            count = int(reader.header.point_count)
            check_points(path, count, memory_limit)
            points = np.empty((count, 3), dtype=np.float64)
            for chunk in _chunks(path, reader):
                n = len(chunk)
                points[done:done + n] = np.column_stack([chunk.x, chunk.y, chunk.z])
                done += n
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - laspy and lazrs raise many kinds on a bad file
        raise InputError(f"{path}: not a readable LAS/LAZ file: {_why(exc, count)}"
                         ) from None
    if done != count:
        raise InputError(f"{path}: truncated: {done:,} of the {count:,} "
                         f"{plural(count, 'point')} its header declares")
    return points


def _chunks(path: Path, reader: Any) -> Iterator[Any]:
    """The reader's points, :data:`LAS_CHUNK` at a time, each read with the decoder's output
    on stderr captured (see :func:`_decoding`)."""
    chunks = reader.chunk_iterator(LAS_CHUNK)
    while True:
        with _decoding(path):
            chunk = next(chunks, None)
        if chunk is None:
            return
        yield chunk


class _Panic(Exception):
    """A Rust panic in lazrs (``pyo3_runtime.PanicException``, a BaseException), as an
    Exception: its message is the decoder's."""


@contextmanager
def _decoding(path: Path) -> Iterator[None]:
    """A call into laspy and lazrs: what the decoder prints on stderr (a panic's message and
    backtrace) captured and dropped, a panic raised as :class:`_Panic`, and any other output
    passed on."""
    with stderr_captured() as printed:
        try:
            yield
        except BaseException as exc:
            if type(exc).__name__ != "PanicException":
                raise
            raise _Panic(one_line(exc)) from None
    if printed and not any("panicked at" in line for line in printed):
        print("\n".join(printed), file=sys.stderr)


#: The decoders' messages for a file that ends early, and what they mean.
_CUT_SHORT = ("failed to fill whole buffer", "buffer size must be a multiple of element size",
              "unexpected end of file", "UnexpectedEof")


def _why(exc: Exception, count: int) -> str:
    """Why laspy or lazrs failed, in words: points that end early, a decoder that failed on
    corrupt data, or the library's own message."""
    text = one_line(exc)
    if isinstance(exc, _Panic):
        return f"its compressed points are corrupt (the LAZ decoder failed: {text})"
    if any(cut in text for cut in _CUT_SHORT):
        return (f"its points end before the {count:,} its header declares (truncated or "
                "corrupt)")
    if isinstance(exc, MemoryError):
        return "not enough memory to decode it"
    return text if len(text) > 3 else f"{type(exc).__name__}: {text}"


def _quiet(name: str) -> None:
    """A library's log records kept off stderr when the program has set no logging up: a
    NullHandler on its logger (Python's last-resort handler prints them otherwise)."""
    logger = logging.getLogger(name)
    if not any(isinstance(h, logging.NullHandler) for h in logger.handlers):
        logger.addHandler(logging.NullHandler())


def read_e57(path: Path, memory_limit: int | None = None) -> np.ndarray:
    """An E57 file's points, metres: every scan's valid points placed by its pose (the file's
    common frame)."""
    import pye57


    if path.stat().st_size == 0:  # libE57Format: "an unrecoverable inconsistent internal state"
        raise InputError(f"{path}: not a readable E57 file: empty")
    try:
        e57 = pye57.E57(str(path))
    except Exception as exc:  # noqa: BLE001 - libE57Format's errors
        raise InputError(f"{path}: not a readable E57 file: {one_line(exc)}") from None
    try:
        scans = e57.scan_count
        if scans == 0:
            raise InputError(f"{path}: no scans")
        check_points(path, sum(int(e57.get_header(i).point_count) for i in range(scans)),
                     memory_limit)
        parts = []
        for i in range(scans):
            data = e57.read_scan(i, transform=True, ignore_missing_fields=True)
            xyz = np.column_stack([np.asarray(data[k], dtype=np.float64)
                                   for k in ("cartesianX", "cartesianY", "cartesianZ")])
            invalid = data.get("cartesianInvalidState")
            if invalid is not None:
                xyz = xyz[np.asarray(invalid) == 0]
            parts.append(xyz)
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001
        raise InputError(f"{path}: cannot read its scans: {one_line(exc)}") from None
    finally:
        e57.close()
    return np.vstack(parts)
