"""SHA-256 of input files: what identifies a truth across results whose paths were written
differently (``pcmapq compare``), and what a batch row's inputs must still be to reuse it."""

from __future__ import annotations

import hashlib
from pathlib import Path

#: Bytes read at a time.
CHUNK = 1 << 20


def sha256_file(path: str | Path) -> str:
    """The SHA-256 of a file's bytes, hex."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(CHUNK):
            digest.update(block)
    return digest.hexdigest()
