"""Writing outputs whole or not at all."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

import numpy as np

from pcmapq.core.errors import InputError

#: The property (PLY) or field (PCD) of a cloud file that holds each point's scan: the mean
#: index of the scans it came from (:mod:`pcmapq.mapping.scan_map`).
SCAN = "scan"


class OutputSet:
    """The output files of one run, all or nothing. A file written with ``outputs=`` this set
    (:func:`atomic_file`) waits, whole, in a temporary file beside its target; :meth:`commit`
    renames them all into place once every output is produced, and :meth:`discard` (or leaving
    a ``with`` block by an error) removes them, so none of the run's outputs appears."""

    def __init__(self) -> None:
        self._staged: list[tuple[str, Path]] = []

    def __enter__(self) -> OutputSet:
        return self

    def __exit__(self, kind: type[BaseException] | None, *_: object) -> None:
        if kind is not None:
            self.discard()

    def stage(self, tmp: str, target: Path) -> None:
        """Hold the finished temporary file ``tmp`` until :meth:`commit` moves it to
        ``target``."""
        self._staged.append((tmp, target))

    def commit(self) -> list[Path]:
        """Rename every staged file into place (``os.replace``, in the order written); the
        targets. A rename that fails (an OS fault) removes the files not yet renamed."""
        done: list[Path] = []
        try:
            while self._staged:
                tmp, target = self._staged[0]
                os.replace(tmp, target)
                self._staged.pop(0)
                done.append(target)
        except OSError as exc:
            self.discard()
            raise InputError(f"{target}: cannot write: {one_line(exc)}") from None
        return done

    def discard(self) -> None:
        """Remove every staged temporary file: no output of the set is written."""
        for tmp, _ in self._staged:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        self._staged.clear()


def write_atomic(path: Path, data: str | bytes, outputs: OutputSet | None = None) -> None:
    """Write ``data`` (str as UTF-8) to ``path`` atomically (see :func:`atomic_file`)."""
    with atomic_file(path, outputs) as f:
        f.write(data.encode("utf-8") if isinstance(data, str) else data)


@contextlib.contextmanager
def atomic_file(path: Path, outputs: OutputSet | None = None) -> Iterator[BinaryIO]:
    """A binary file to write ``path`` through, whole or not at all: the bytes go into a
    temporary file in the target's directory, which replaces the target (``os.replace``) when
    the block ends without an error, or, with ``outputs``, when that set is committed. A
    symlink is written through: its target is replaced, the link stays. On failure the
    temporary file is removed, any old file is left as it was, and an OSError becomes
    InputError. The new file gets the usual mode (0o666 less the umask), or the old file's
    mode when replacing one."""
    path = Path(path)
    target = Path(os.path.realpath(path))
    tmp: str | None = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
        with os.fdopen(fd, "wb") as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, _target_mode(target))
        if outputs is None:
            os.replace(tmp, target)
        else:
            outputs.stage(tmp, target)
        tmp = None
    except OSError as exc:
        raise InputError(f"{path}: cannot write: {one_line(exc)}") from None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


def write_ros_map(path: Path, image: np.ndarray, resolution: float,
                  origin: tuple[float, float] = (0.0, 0.0),
                  outputs: OutputSet | None = None) -> Path:
    """Save an occupancy image (uint8 grey values, ROS's 0 occupied, 254 free, 205 unknown) at
    ``path`` (.png or .pgm) with its map_server YAML beside it (same stem): ``resolution``
    metres per pixel, ``origin`` (x, y) metres of the image's lower-left corner, yaw 0, ROS's
    default thresholds. Both are written whole (:func:`write_atomic`; with ``outputs``, when
    that set is committed). Returns ``path``."""
    import cv2  # here: the command line's help reads this module's one_line, not OpenCV

    path = Path(path)
    ok, encoded = cv2.imencode(path.suffix or ".png", np.asarray(image, dtype=np.uint8))
    if not ok:
        raise InputError(f"{path}: cannot be written as an image")
    write_atomic(path, encoded.tobytes(), outputs)
    write_atomic(path.with_suffix(".yaml"),
                 f"image: {path.name}\nresolution: {resolution}\n"
                 f"origin: [{origin[0]}, {origin[1]}, 0.0]\n"
                 "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n", outputs)
    return path


def one_line(exc: BaseException) -> str:
    """An exception's message on one line: ``strerror`` for OS errors, else the first line."""
    text = str(getattr(exc, "strerror", None) or exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _target_mode(path: Path) -> int:
    """Permission bits for the output: the existing file's, or 0o666 less the umask."""
    try:
        return path.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def write_cloud(path: Path, points: np.ndarray, outputs: OutputSet | None = None,
                scan: np.ndarray | None = None) -> None:
    """Write points (N, 3, metres) as .ply or .pcd (binary float32), whole or not at all (with
    ``outputs``: when that set is committed); a symlink is written through. scan: (N,) each
    point's scan (:mod:`pcmapq.mapping.scan_map`), written as the float property ``scan``."""
    import open3d as o3d

    if path.suffix.lower() not in (".ply", ".pcd"):
        raise InputError(f"{path}: a map is written as .ply or .pcd")
    cloud = o3d.t.geometry.PointCloud(o3d.core.Tensor(np.asarray(points, dtype=np.float32)))
    if scan is not None:
        cloud.point[SCAN] = o3d.core.Tensor(np.asarray(scan, dtype=np.float32).reshape(-1, 1))
    target = Path(os.path.realpath(path))
    tmp = target.with_name(f".{target.stem}.{os.getpid()}.tmp{target.suffix}")
    staged = False
    try:
        if not o3d.t.io.write_point_cloud(str(tmp), cloud):
            raise InputError(f"{path}: cannot write")
        os.chmod(tmp, _target_mode(target))
        if outputs is None:
            os.replace(tmp, target)
        else:
            outputs.stage(str(tmp), target)
            staged = True
    except OSError as err:
        raise InputError(f"{path}: cannot write: {err.strerror or err}") from None
    finally:
        if not staged:
            tmp.unlink(missing_ok=True)


def same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file: ``os.path.samefile`` when both exist (links and hard
    links included), else the same resolved path."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()
