"""CARMEN laser logs (``.log``, ``.log.gz``): the map is the laser endpoints at the logged poses.

Only ``FLASER`` lines are read; every other line (``ODOM``, ``PARAM``, ``NEFF``, ``# ...``) is
ignored. A ``FLASER`` line is::

    FLASER n r_1 ... r_n x y theta odom_x odom_y odom_theta timestamp host logger_timestamp

with ``n`` ranges in metres and ``x y theta`` the pose of the laser in the world frame (metres,
radians; SLAM-corrected in a ``*-corrected.log``). Beam ``i`` points at ``-pi/2 + i * step``
in the laser frame, as CARMEN's ``readlog.c`` assumes for these old messages: ``step`` is 1
degree for 180 or 181 beams, 0.5 degree for 360 or 361, and ``pi / (n - 1)`` otherwise.

A SICK reports "no return" as its maximum range (81.83, 81.91, 50, 32.767 m, ...): the largest
range of a log, when readings within 0.2 % of it are frequent (see :func:`no_return_range`),
is taken as that code and those readings are dropped. Readings above ``max_range`` are dropped
too: long beams graze walls and pass through glass.

Parsing is vectorised: the ``FLASER`` lines of each beam count are read by one
``np.loadtxt`` call, and all endpoints are computed at once.
"""

from __future__ import annotations

import gzip
import warnings
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.words import plural
from pcmapq.io.clouds import PointMap
from pcmapq.io.formats import CARMEN_SUFFIXES
from pcmapq.io.writers import one_line

#: Readings above this are dropped by default, metres.
DEFAULT_MAX_RANGE = 30.0

#: Readings within this fraction below a log's largest range count as that "no return" code.
NO_RETURN_TOLERANCE = 0.002

#: The largest range is a "no return" code when at least this share of all readings (and at
#: least ``NO_RETURN_MIN_COUNT`` readings) lie within ``NO_RETURN_TOLERANCE`` of it.
NO_RETURN_MIN_SHARE = 5e-4
NO_RETURN_MIN_COUNT = 10

#: Fields of a FLASER line after the word FLASER besides its n ranges: n itself, the laser pose,
#: the odometry pose, timestamp, host, logger timestamp.
_EXTRA_FIELDS = 10


def is_carmen(path: Path) -> bool:
    """True when the file name ends with ``.log`` or ``.log.gz`` (any case)."""
    return path.name.lower().endswith(CARMEN_SUFFIXES)


def load_carmen(path: str | Path, max_range: float = DEFAULT_MAX_RANGE) -> PointMap:
    """Load a CARMEN log as a 2D point map.

    Returns a :class:`PointMap` whose points are the laser endpoints in the world frame of the
    logged (``FLASER x y theta``) poses, (N, 3) float64 metres with z = 0, in log order.
    Readings that are "no return" codes, not positive, or above ``max_range`` (metres) give no
    point. Raises :class:`InputError` (one line naming the file) on a bad log.
    """
    path = Path(path)
    poses, ranges, angles = read_flaser(path)
    xy = endpoints(poses, ranges, angles, max_range)
    if len(xy) == 0:
        raise InputError(f"{path}: no laser reading within {max_range:g} m")
    points = np.zeros((len(xy), 3), dtype=np.float64)
    points[:, :2] = xy
    return PointMap(path, points, is_3d=False, kind="carmen")


@dataclass(frozen=True)
class LaserScans:
    """The scans of a CARMEN log's ``FLASER`` lines, in log order: ``poses`` (K, 3) laser pose
    x, y (metres) and theta (radians) in the world frame; ``ranges`` (K, B) metres and
    ``angles`` (K, B) radians in the laser frame, B the largest beam count, NaN where there is
    no reading (see :func:`read_flaser`); ``stamps`` (K,) the lines' timestamps, seconds."""

    poses: np.ndarray
    ranges: np.ndarray
    angles: np.ndarray
    stamps: np.ndarray


def read_flaser(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The poses, ranges and angles of :func:`read_laser_scans`.

    A reading with no return (the log's "no return" code, a non-positive or non-finite range)
    and the padding of a scan with fewer than B beams are NaN in ``ranges``.
    """
    scans = read_laser_scans(path)
    return scans.poses, scans.ranges, scans.angles


def read_laser_scans(path: str | Path) -> LaserScans:
    """Every ``FLASER`` scan of a log with its pose and timestamp (:class:`LaserScans`);
    InputError (one line naming the file, and the line) on a bad log."""
    path = Path(path)
    numbers, lines = flaser_lines(path)
    counts = _beam_counts(path, numbers, lines)
    rows = np.asarray(lines, dtype=object)
    # every line's values parsed (its beam count checked against them) before the padded
    # tables of the largest count are allocated: "FLASER 100000000 1 2 3" allocates nothing
    groups = {int(n): np.flatnonzero(counts == n) for n in np.unique(counts)}
    tables = {n: _parse_group(path, numbers[which], rows[which].tolist(), n)
              for n, which in groups.items()}
    width = int(counts.max())
    poses = np.empty((len(lines), 3), dtype=np.float64)
    stamps = np.empty(len(lines), dtype=np.float64)
    ranges = np.full((len(lines), width), np.nan)
    angles = np.full((len(lines), width), np.nan)
    for n, which in groups.items():
        table = tables[n]
        ranges[which, :n] = table[:, 1:n + 1]
        poses[which] = table[:, n + 1:n + 4]
        stamps[which] = table[:, n + 7]
        angles[which, :n] = beam_angles(n)
    if not np.isfinite(poses).all():
        raise InputError(f"{path}: a FLASER pose is not a finite number")
    with np.errstate(invalid="ignore"):
        ranges[~((ranges > 0) & np.isfinite(ranges))] = np.nan
        code = no_return_range(ranges)
        if code is not None:
            ranges[ranges >= code * (1.0 - NO_RETURN_TOLERANCE)] = np.nan
    return LaserScans(poses, ranges, angles, stamps)


def _kept(poses: np.ndarray, ranges: np.ndarray, angles: np.ndarray,
          max_range: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The poses (K, 3), the world headings of the beams (K, B) and which readings give a
    point (K, B): positive, at most ``max_range`` metres, finite heading."""
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
    ranges = np.asarray(ranges, dtype=np.float64).reshape(len(poses), -1)
    heading = poses[:, 2:3] + np.broadcast_to(angles, ranges.shape)
    with np.errstate(invalid="ignore"):
        keep = (ranges > 0) & (ranges <= max_range) & np.isfinite(heading)
    return poses, heading, keep


def endpoints(poses: np.ndarray, ranges: np.ndarray, angles: np.ndarray,
              max_range: float = DEFAULT_MAX_RANGE) -> np.ndarray:
    """Beam endpoints in the world frame, (M, 2) metres, scan by scan in beam order.

    poses: (K, 3) laser poses x, y (metres), theta (radians) in the world frame.
    ranges: (K, B) metres; NaN, non-positive and above-``max_range`` readings give no point.
    angles: (K, B) or (B,) beam angles in the laser frame, radians.
    """
    poses, heading, keep = _kept(poses, ranges, angles, max_range)
    r = np.asarray(ranges, dtype=np.float64).reshape(heading.shape)[keep]
    a = heading[keep]
    k = np.broadcast_to(np.arange(len(poses))[:, None], keep.shape)[keep]
    return np.column_stack([poses[k, 0] + r * np.cos(a), poses[k, 1] + r * np.sin(a)])


def endpoint_scans(poses: np.ndarray, ranges: np.ndarray, angles: np.ndarray,
                   max_range: float = DEFAULT_MAX_RANGE) -> np.ndarray:
    """(M,) the scan index of each of :func:`endpoints`' points (same arguments)."""
    poses, _, keep = _kept(poses, ranges, angles, max_range)
    return np.repeat(np.arange(len(poses)), np.count_nonzero(keep, axis=1))


def beam_angles(n: int) -> np.ndarray:
    """Angles of the n beams of a FLASER scan in the laser frame, radians (x ahead, y left):
    ``-pi/2 + i * step``, with CARMEN's guess of ``step`` for a SICK (see the module doc)."""
    if n in (180, 181):
        step = np.pi / 180.0
    elif n in (360, 361):
        step = np.pi / 360.0
    else:
        step = np.pi / max(n - 1, 1)
    return -np.pi / 2.0 + step * np.arange(n)


def no_return_range(ranges: np.ndarray) -> float | None:
    """The log's "no return" code, metres: its largest range when readings within
    ``NO_RETURN_TOLERANCE`` of it are frequent (a real wall is rarely seen at exactly the
    longest range, a SICK's no-return value is reported over and over); else None.
    ``ranges`` holds metres, NaN for nothing. Limit: a log whose longest readings are a real
    wall seen many times at the same range would lose them."""
    valid = ranges[np.isfinite(ranges)]
    if len(valid) == 0:
        return None
    top = float(valid.max())
    near = int(np.count_nonzero(valid >= top * (1.0 - NO_RETURN_TOLERANCE)))
    return top if near >= max(NO_RETURN_MIN_COUNT, NO_RETURN_MIN_SHARE * len(valid)) else None


def flaser_lines(path: Path) -> tuple[np.ndarray, list[str]]:
    """The FLASER lines of a log (gzip-compressed or plain, told by its first bytes): their
    (K,) 1-based line numbers in the file, and the lines without the word FLASER. Raises
    InputError when there is none or the file cannot be read."""
    try:
        with path.open("rb") as f:
            data = f.read()
        if data[:2] == b"\x1f\x8b":
            data = gzip.decompress(data)
        text = data.decode("utf-8")
    except (OSError, EOFError, zlib.error, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read as a CARMEN log: {one_line(exc)}") from None
    numbered = [(i, line[7:]) for i, line in enumerate(text.splitlines(), start=1)
                if line.startswith(("FLASER ", "FLASER\t"))]
    if not numbered:
        raise InputError(f"{path}: no FLASER line (not a CARMEN laser log?)")
    numbers, lines = zip(*numbered, strict=True)
    return np.asarray(numbers, dtype=np.int64), list(lines)


def _beam_counts(path: Path, numbers: np.ndarray, lines: list[str]) -> np.ndarray:
    """(K,) int: the beam count n that opens each FLASER line (after the word FLASER)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            first = np.loadtxt(lines, usecols=0, dtype=np.float64, ndmin=1, comments=None)
    except ValueError:
        first = None
    if first is None or not (np.isfinite(first) & (first >= 1) & (first == np.round(first))).all():
        _raise_first_bad_line(path, numbers, lines)
    return first.astype(np.int64)


def _parse_group(path: Path, numbers: np.ndarray, lines: list[str], n: int) -> np.ndarray:
    """FLASER lines of n beams as a (k, n + 10) float table: n, ranges, laser pose, odometry
    pose, timestamp, host (0), logger timestamp. ``numbers``: their line numbers in the file."""
    try:
        table = np.loadtxt(lines, dtype=np.float64, ndmin=2, comments=None,
                           converters={n + 8: lambda _host: 0.0})
    except (ValueError, IndexError):
        table = None
    if table is None or table.shape[1] != n + _EXTRA_FIELDS:
        _raise_first_bad_line(path, numbers, lines)
    return table


def _raise_first_bad_line(path: Path, numbers: np.ndarray, lines: list[str]) -> NoReturn:
    """Raise InputError naming the first bad FLASER line (its line number in the file) and
    its problem. Only called after a vectorised parse failed, so its loop costs nothing on a
    good log."""
    for number, line in zip(numbers.tolist(), lines, strict=True):
        problem = _line_problem(line)
        if problem is not None:
            raise InputError(f"{path}: line {number}: {problem}")
    raise InputError(f"{path}: FLASER lines cannot be parsed")


def _line_problem(line: str) -> str | None:
    """What is wrong with one FLASER line (without the word FLASER), or None."""
    fields = line.split()
    try:
        n = int(fields[0]) if fields else 0
    except ValueError:
        return f"FLASER beam count {fields[0]!r} is not an integer"
    if n < 1:
        return "FLASER beam count missing or not positive"
    if len(fields) != n + _EXTRA_FIELDS:
        return (f"FLASER with {n} {plural(n, 'beam')} needs {n + _EXTRA_FIELDS + 1} fields, "
                f"got {len(fields) + 1}")
    names = [f"range {i}" for i in range(1, n + 1)] + [
        "x", "y", "theta", "odom_x", "odom_y", "odom_theta", "timestamp"]
    for name, field in zip(names, fields[1:n + 8], strict=True):
        try:
            float(field)
        except ValueError:
            return f"FLASER {name} {field!r} is not a number"
    try:
        float(fields[n + 9])
    except ValueError:
        return f"FLASER logger timestamp {fields[n + 9]!r} is not a number"
    return None
