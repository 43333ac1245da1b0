"""The files of ROS recordings that rosbags does not open as they are: a storage file
compressed whole (``.mcap.zstd``, ``.db3.zstd``: rosbag2's file compression, or ``zstd FILE``'s
``.zst``), read from a decompressed copy; and ROS 1 bags of an old format, said in words with
the way to convert them."""

from __future__ import annotations

import shutil
import tempfile
import threading
from pathlib import Path

from pcmapq.core.errors import InputError
from pcmapq.io.formats import COMPRESSED_SUFFIXES
from pcmapq.io.writers import one_line

#: Decompressed copies kept at once (a map and a truth, read again by each reader).
KEPT = 4

_copies: dict[tuple[str, int, int], Path] = {}
_made = 0
_folder: tempfile.TemporaryDirectory | None = None
_lock = threading.Lock()


def is_compressed(path: Path) -> bool:
    """Whether ``path`` names a storage file compressed whole (:data:`COMPRESSED_SUFFIXES`)."""
    return Path(path).name.lower().endswith(COMPRESSED_SUFFIXES)


def decompressed(path: Path) -> Path:
    """The storage file a ``.mcap.zstd`` (...) holds, decompressed into a temporary folder
    removed at exit, once for the last :data:`KEPT` files read (the input is not modified);
    InputError naming ``path`` when it is not zstd data or is cut short."""
    zstd = zstd_module()
    if zstd is None:  # pragma: no cover - rosbags depends on backports.zstd before 3.14
        raise InputError(f"{path}: a zstd-compressed recording; decompress it first: "
                         f"zstd -d {path}")
    stat = Path(path).stat()
    key = (str(Path(path).resolve()), stat.st_mtime_ns, stat.st_size)
    global _folder, _made
    with _lock:
        if key in _copies:
            _copies[key] = _copies.pop(key)  # the most recently used last
            return _copies[key]
        if _folder is None:
            _folder = tempfile.TemporaryDirectory(prefix="pcmapq-")
        while len(_copies) >= KEPT:
            shutil.rmtree(_copies.pop(next(iter(_copies))).parent, ignore_errors=True)
        name = Path(path).name
        target = Path(_folder.name) / str(_made) / name[:name.lower().rfind(".zst")]
        _made += 1
        target.parent.mkdir()
        try:
            with zstd.open(path, "rb") as source, target.open("wb") as out:
                shutil.copyfileobj(source, out, 1 << 20)
        except (zstd.ZstdError, EOFError, OSError) as exc:
            shutil.rmtree(target.parent, ignore_errors=True)
            raise InputError(f"{path}: not a readable zstd-compressed recording: "
                             f"{one_line(exc)}") from None
        _copies[key] = target
        return target


def zstd_module():
    """The zstd module rosbags itself uses (the standard library's from Python 3.14, else
    backports.zstd), or None."""
    try:
        from compression import zstd  # type: ignore[import-not-found]
    except ImportError:
        try:
            from backports import zstd  # type: ignore[import-not-found,no-redef]
        except ImportError:  # pragma: no cover
            return None
    return zstd


def old_format(path: Path, error: BaseException) -> str | None:
    """Why a ``.bag`` rosbags refused (``error``) cannot be read, when it is a ROS 1 bag of a
    format or index rosbags does not read, with how to convert it; None otherwise."""
    if Path(path).suffix.lower() != ".bag":
        return None
    try:
        with open(path, "rb") as f:
            magic = f.readline(64)
    except OSError:
        return None
    name = next((n for n in (b"#ROSRECORD V", b"#ROSLOG V", b"#ROSBAG V")
                 if magic.startswith(n)), None)
    if name is None:
        return None
    version = magic[len(name) - 1:].strip().decode("ascii", "replace")
    if version == "V1.2":
        return ("a ROS 1 bag of format V1.2 (ROS 0.5 to 1.0), which rosbags does not "
                f"read: convert it to V2.0 with ROS 1's 'rosbag reindex {path}' (it keeps "
                "the original beside it as .orig.bag)")
    if version != "V2.0":
        return (f"a ROS 1 bag of format {version}, which rosbags does not read (it reads "
                "V2.0; ROS 1's rosbag reads V1.2 and V2.0)")
    text = "" if isinstance(error, AssertionError) else one_line(error)
    if isinstance(error, AssertionError) or "version" in text or "not indexed" in text:
        return ("a ROS 1 bag (V2.0) whose index rosbags cannot read (index records of an "
                f"older rosbag, none, or damaged{': ' + text if text else ''}); rebuild its "
                f"index with ROS 1's 'rosbag reindex {path}'")
    return None
