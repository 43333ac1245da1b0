"""The C heap's free memory handed back to the system.

glibc keeps the pages of freed blocks smaller than its mmap threshold (which rises to 32 MiB as
large blocks are freed) in its heap, so a step that filled the heap and finished leaves them
resident while the next step maps fresh pages for its own arrays. :func:`release_free_memory`
returns them (``malloc_trim``); it does nothing on another C library."""

from __future__ import annotations

import ctypes
import functools
import os


@functools.cache
def glibc() -> ctypes.CDLL | None:
    """The process's C library when it is glibc (mallopt and malloc_trim), else None."""
    try:
        if not os.confstr("CS_GNU_LIBC_VERSION"):
            return None
        libc = ctypes.CDLL(None)
    except (ValueError, OSError, AttributeError):  # not glibc, or no os.confstr
        return None
    if not (hasattr(libc, "mallopt") and hasattr(libc, "malloc_trim")):
        return None
    libc.mallopt.argtypes, libc.mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    libc.malloc_trim.argtypes, libc.malloc_trim.restype = [ctypes.c_size_t], ctypes.c_int
    return libc


def release_free_memory() -> bool:
    """Hand the heap's free pages back to the system; whether the C library could."""
    libc = glibc()
    return libc is not None and bool(libc.malloc_trim(0))
