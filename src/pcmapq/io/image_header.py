"""An image's dimensions read from its header, so that its decoded size is checked against the
memory guard before OpenCV allocates it (a 1 MB PNG can declare 30000 x 30000 pixels).

PNG (the IHDR chunk at a fixed offset), PGM / PPM (a text header) and BMP (fixed offsets) are
read here; other formats (JPEG) are left to OpenCV's own limit on pixels. A PNG's chunks are
checked too (lengths, CRCs), so that libpng has nothing to print.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

from pcmapq.core import memory
from pcmapq.core.errors import InputError

__all__ = ["check_image_size", "check_png_chunks", "declared_size"]

_PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: PNG colour type -> channels OpenCV decodes (a palette becomes BGR).
_PNG_CHANNELS = {0: 1, 2: 3, 3: 3, 4: 2, 6: 4}


def declared_size(path: Path) -> tuple[int, int, int] | None:
    """(rows, cols, bytes per decoded pixel) from the image's header, or None for a format
    not read here. InputError for a header too short or malformed to hold them."""
    with path.open("rb") as f:
        head = f.read(512)
    if head.startswith(_PNG_MAGIC):
        return _png(path, head)
    if head[:2] in (b"P2", b"P3", b"P5", b"P6"):
        return _netpbm(path, head)
    if head.startswith(b"BM"):
        return _bmp(path, head)
    return None


def check_image_size(path: Path, memory_limit: int | None = None) -> None:
    """InputError (one line) when the image's declared pixels would need more memory to read
    and classify than the memory guard allows (:mod:`pcmapq.core.memory`; ``memory_limit`` bytes,
    None: the default limit)."""
    size = declared_size(path)
    if size is None:
        return
    with path.open("rb") as f:
        is_png = f.read(len(_PNG_MAGIC)) == _PNG_MAGIC
    if is_png:
        check_png_chunks(path)
    rows, cols, per_pixel = size
    need = int(memory.BASE + rows * cols * (per_pixel + _CLASSIFY_BYTES))
    memory.guard(need, memory_limit, f"{path} ({cols} x {rows} pixels declared in its header)")


#: Bytes per pixel, beyond the decoded image, of turning it into cell states (the int32 sum of
#: its channels, the transparency mask, the int8 state).
_CLASSIFY_BYTES = 6


def check_png_chunks(path: Path) -> None:
    """InputError when a PNG's chunks run past the end of the file, one fails its CRC, or there
    is no IEND: libpng would print ``libpng error: ...`` on stderr before OpenCV gives up. One
    step per chunk (a few hundred in a large map), one CRC pass over the file."""
    data = memoryview(path.read_bytes())
    at = len(_PNG_MAGIC)
    while at + 12 <= len(data):
        length = int.from_bytes(data[at:at + 4], "big")
        kind = bytes(data[at + 4:at + 8]).decode("latin-1")
        end = at + 12 + length
        if end > len(data):
            raise InputError(f"{path}: truncated PNG (chunk {kind!r} at byte {at} needs "
                             f"{length} bytes, the file ends before)")
        if zlib.crc32(data[at + 4:end - 4]) != int.from_bytes(data[end - 4:end], "big"):
            raise InputError(f"{path}: corrupt PNG (CRC error in chunk {kind!r} at byte {at})")
        if kind == "IEND":
            return
        at = end
    raise InputError(f"{path}: truncated PNG (no IEND chunk)")


def _png(path: Path, head: bytes) -> tuple[int, int, int]:
    """The IHDR of a PNG: width and height at bytes 16-24, then bit depth and colour type."""
    if len(head) < 26 or head[12:16] != b"IHDR":
        raise InputError(f"{path}: corrupt PNG header (no IHDR chunk)")
    cols, rows, depth, colour = struct.unpack(">IIBB", head[16:26])
    if colour not in _PNG_CHANNELS:
        raise InputError(f"{path}: corrupt PNG header (colour type {colour})")
    return rows, cols, _PNG_CHANNELS[colour] * (2 if depth == 16 else 1)


def _netpbm(path: Path, head: bytes) -> tuple[int, int, int]:
    """A PGM / PPM text header: magic, width, height, maxval, with ``#`` comments."""
    words: list[bytes] = []
    for line in head.split(b"\n"):
        words += line.split(b"#", 1)[0].split()
        if len(words) >= 4:
            break
    try:
        cols, rows, maxval = (int(w) for w in words[1:4])
    except ValueError:
        raise InputError(f"{path}: corrupt PGM/PPM header") from None
    channels = 1 if head[:2] in (b"P2", b"P5") else 3
    return rows, cols, channels * (2 if maxval > 255 else 1)


def _bmp(path: Path, head: bytes) -> tuple[int, int, int]:
    """A BMP's info header: width and height (negative: top-down) at bytes 18-26, bits per
    pixel at 28."""
    if len(head) < 30:
        raise InputError(f"{path}: corrupt BMP header")
    cols, rows, _, bits = struct.unpack("<iiHH", head[18:30])
    return abs(rows), abs(cols), max(bits // 8, 1)
