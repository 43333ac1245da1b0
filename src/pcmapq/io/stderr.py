"""What C libraries print on stderr while they read a file, captured so that it becomes the one
line of an InputError (RPly inside Open3D, libpng inside OpenCV print their errors there and
go on or give up) instead of noise beside it."""

from __future__ import annotations

import os
import sys
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["stderr_captured", "stderr_uncaptured"]

#: One capture at a time: two threads swapping descriptor 2 at once (the map and the truth are
#: read in parallel) would each restore the other's sink and leave stderr pointing at a file.
_ONE_AT_A_TIME = threading.Lock()


@contextmanager
def stderr_captured() -> Iterator[list[str]]:
    """File descriptor 2 redirected to a temporary file in the block; the list yielded holds,
    after the block, the lines written there. Meant for one library call: output of other
    threads in the meantime is captured too; captures in other threads wait for this one."""
    with _ONE_AT_A_TIME, tempfile.TemporaryFile() as sink:
        sys.stderr.flush()
        saved, lines = os.dup(2), []
        os.dup2(sink.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            lines += sink.read().decode("utf-8", errors="replace").splitlines()


@contextmanager
def stderr_uncaptured() -> Iterator[None]:
    """Descriptor 2 left as it is in the block: no capture in another thread meanwhile (one
    under way is waited for). For a line meant for the user (a warning) while another thread
    may be reading a file, whose capture would swallow it. Not inside a capture."""
    with _ONE_AT_A_TIME:
        yield
