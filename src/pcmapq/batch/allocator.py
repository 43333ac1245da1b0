"""A row runs with glibc's own allocator thresholds, even in a process started with Dask's
worker environment.

A Dask nanny starts its worker processes with ``MALLOC_TRIM_THRESHOLD_=65536``
(``distributed.nanny.pre-spawn-environ``); it sets it in its own process's ``os.environ`` to do
so, and leaves it there, so that a Python program that started a LocalCluster passes it on to
every process it starts afterwards, local batch workers included. Set, it turns off
glibc's dynamic mmap threshold, so that every allocation of 128 KiB or more (most of a map's
NumPy arrays and OpenCV images) is a fresh ``mmap`` whose pages fault in anew and go back to the
system when freed: a batch then spends much of its CPU time faulting pages in
(docs/benchmarks.md, Batches). :func:`glibc_thresholds` gives a row the thresholds
glibc's dynamic rule rises to in a process started without it (mmap 32 MiB on 64-bit, trim
twice that), then puts back the environment's and returns the free memory to the system
(``malloc_trim``), so that between rows the worker holds the memory Dask expects."""

from __future__ import annotations

import contextlib
import ctypes
import os
from collections.abc import Iterator, Mapping

from pcmapq.core.heap import glibc

#: mallopt's parameters (malloc.h).
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
#: glibc's mmap threshold at a process's start, and the most its dynamic rule raises it to
#: (DEFAULT_MMAP_THRESHOLD_MAX: 32 MiB on 64-bit); the trim threshold follows at twice it.
MMAP_START = 128 * 1024
MMAP_MAX = 4 * 1024 * 1024 * ctypes.sizeof(ctypes.c_long)


def start_environment() -> Mapping[str, str]:
    """The environment this process started with, which glibc read its thresholds from
    (/proc/self/environ); ``os.environ`` where that is unreadable. Not ``os.environ`` itself:
    a process that started a LocalCluster has Dask's worker variables there, set after its own
    start."""
    try:
        with open("/proc/self/environ", "rb") as f:
            entries = f.read().split(b"\0")
    except OSError:
        return os.environ
    pairs = (os.fsdecode(e).partition("=") for e in entries if b"=" in e)
    return {name: value for name, _, value in pairs}


def fixed_trim_threshold(environ: Mapping[str, str] | None = None) -> int | None:
    """The trim threshold an environment (default: :func:`start_environment`) fixes
    (``MALLOC_TRIM_THRESHOLD_``, as Dask's workers have it), bytes, when the C library is glibc
    and the mmap threshold is not fixed too (``MALLOC_MMAP_THRESHOLD_``: a choice of its own,
    left alone); else None."""
    environ = start_environment() if environ is None else environ
    trim = environ.get("MALLOC_TRIM_THRESHOLD_")
    if trim is None or "MALLOC_MMAP_THRESHOLD_" in environ or glibc() is None:
        return None
    try:
        return int(trim.strip(), 0)
    except ValueError:
        return None


@contextlib.contextmanager
def glibc_thresholds() -> Iterator[bool]:
    """Within: glibc's thresholds as its dynamic rule reaches them (mmap :data:`MMAP_MAX`, trim
    twice that) when the process started with a fixed trim threshold
    (:func:`fixed_trim_threshold`); after: the thresholds it started with again, and the free
    memory returned to the system. Nothing where it started with none, or on another C library.
    Yields whether it changed them. One caller at a time: the thresholds are the process's."""
    trim = fixed_trim_threshold()
    libc = None if trim is None else glibc()
    if libc is None:
        yield False
        return
    libc.mallopt(M_MMAP_THRESHOLD, MMAP_MAX)
    libc.mallopt(M_TRIM_THRESHOLD, 2 * MMAP_MAX)
    try:
        yield True
    finally:
        libc.mallopt(M_MMAP_THRESHOLD, MMAP_START)
        libc.mallopt(M_TRIM_THRESHOLD, trim)
        libc.malloc_trim(0)
