"""Survey clouds: LAS and LAZ (laspy with the lazrs backend) and E57 (pye57, libE57Format),
as CloudCompare reads them. Points (N, 3) float64 metres in the file's frame: LAS's scaled
coordinates; an E57's scans each placed by its pose, in the file's common frame. The points a
header declares are checked against the memory limit before any is read; a LAS file is read
in chunks."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.words import plural
from pcmapq.io.writers import one_line

#: Points read from a LAS file at a time (a record is up to 64 kB: a few MB a chunk).
LAS_CHUNK = 100_000


def read_las(path: Path, memory_limit: int | None = None) -> np.ndarray:
    """A LAS or LAZ file's points, metres (its header's scales and offsets applied)."""
    import laspy

    from pcmapq.io.clouds import check_points

    _check_las_header(path)
    try:
        with laspy.open(path, laz_backend=laspy.LazBackend.Lazrs) as reader:
            count = int(reader.header.point_count)
            check_points(path, count, memory_limit)
            points = np.empty((count, 3), dtype=np.float64)
            done = 0
            for chunk in reader.chunk_iterator(LAS_CHUNK):
                n = len(chunk)
                points[done:done + n] = np.column_stack([chunk.x, chunk.y, chunk.z])
                done += n
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - laspy and lazrs raise many kinds on a bad file
        raise InputError(f"{path}: not a readable LAS/LAZ file: {one_line(exc)}") from None
    if done != count:
        raise InputError(f"{path}: truncated: {done:,} of the {count:,} "
                         f"{plural(count, 'point')} its header declares")
    return points


def _check_las_header(path: Path) -> None:
    """Refuse, before laspy reads it, a LAS header whose variable-length records could not fit
    between the header and the points (a corrupt count laspy would spend minutes on)."""
    import struct

    with open(path, "rb") as f:
        head = f.read(104)
    if len(head) < 104 or head[:4] != b"LASF":
        raise InputError(f"{path}: not a readable LAS/LAZ file: no LAS header")
    header_size, offset, records = struct.unpack_from("<HII", head, 94)
    if records * 54 > max(offset - header_size, 0):
        raise InputError(f"{path}: not a readable LAS/LAZ file: its header declares {records:,} "
                         f"variable-length records in {max(offset - header_size, 0):,} bytes")


def read_e57(path: Path, memory_limit: int | None = None) -> np.ndarray:
    """An E57 file's points, metres: every scan's valid points placed by its pose (the file's
    common frame)."""
    import pye57

    from pcmapq.io.clouds import check_points

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
