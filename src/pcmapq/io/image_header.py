"""An image's dimensions read from its header, so that its decoded size is checked against the
memory guard before OpenCV allocates it (a 1 MB PNG can declare 30000 x 30000 pixels).

PNG (the IHDR chunk at a fixed offset), PGM / PPM (a text header) and BMP (fixed offsets) are
read here; other formats (JPEG) are left to OpenCV's own limit on pixels.
"""

from __future__ import annotations

import struct
from pathlib import Path

from pcmapq import memory
from pcmapq.errors import InputError

__all__ = ["check_image_size", "declared_size"]

#: PNG colour type -> channels OpenCV decodes (a palette becomes BGR).
_PNG_CHANNELS = {0: 1, 2: 3, 3: 3, 4: 2, 6: 4}


def declared_size(path: Path) -> tuple[int, int, int] | None:
    """(rows, cols, bytes per decoded pixel) from the image's header, or None for a format
    not read here. InputError for a header too short or malformed to hold them."""
    with path.open("rb") as f:
        head = f.read(512)
    if head.startswith(b"\x89PNG\r\n\x1a\n"):
        return _png(path, head)
    if head[:2] in (b"P2", b"P3", b"P5", b"P6"):
        return _netpbm(path, head)
    if head.startswith(b"BM"):
        return _bmp(path, head)
    return None


def check_image_size(path: Path, memory_limit: int | None = None) -> None:
    """InputError (one line) when the image's declared pixels would need more memory to read
    and classify than the memory guard allows (:mod:`pcmapq.memory`; ``memory_limit`` bytes,
    None: the default limit)."""
    size = declared_size(path)
    if size is None:
        return
    rows, cols, per_pixel = size
    need = int(memory.BASE + rows * cols * (per_pixel + _CLASSIFY_BYTES))
    memory.guard(need, memory_limit, f"{path} ({cols} x {rows} pixels declared in its header)")


#: Bytes per pixel, beyond the decoded image, of turning it into cell states (the int32 sum of
#: its channels, the transparency mask, the int8 state).
_CLASSIFY_BYTES = 6


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
