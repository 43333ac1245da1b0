"""A row's allocator thresholds (pcmapq.batch.allocator): which environments fix glibc's trim
threshold (the one the process started with), and none changed where none is fixed. (Their
effect, page faults in a process started with Dask's worker environment:
tests/e2e/test_batch_allocator.py.)"""

from __future__ import annotations

import os

import pytest

from pcmapq.batch import allocator


@pytest.fixture
def glibc(monkeypatch):
    """A C library with mallopt, whatever this machine's: nothing here calls it."""
    monkeypatch.setattr(allocator, "glibc", lambda: object())


@pytest.mark.parametrize("environ, fixed", [
    ({}, None),
    ({"MALLOC_TRIM_THRESHOLD_": "65536"}, 65536),  # Dask's workers
    ({"MALLOC_TRIM_THRESHOLD_": "0x10000"}, 65536),
    ({"MALLOC_TRIM_THRESHOLD_": "65536", "MALLOC_MMAP_THRESHOLD_": "131072"}, None),
    ({"MALLOC_TRIM_THRESHOLD_": "a lot"}, None),
])
def test_fixed_trim_threshold(glibc, environ, fixed):
    """The trim threshold Dask's environment fixes, bytes; None when unset, unreadable, or
    with the mmap threshold fixed too (a choice of its own, left alone)."""
    assert allocator.fixed_trim_threshold(environ) == fixed


def test_the_environment_the_process_started_with(glibc, monkeypatch):
    """What counts is the environment the process started with, which glibc read, not
    os.environ: there a LocalCluster's nannies leave Dask's worker variables for good."""
    monkeypatch.setenv("PCMAPQ_SET_AFTER_START", "1")
    if os.path.exists("/proc/self/environ"):
        assert "PCMAPQ_SET_AFTER_START" not in allocator.start_environment()
    monkeypatch.setattr(allocator, "start_environment", lambda: {})
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "65536")
    assert allocator.fixed_trim_threshold() is None
    with allocator.glibc_thresholds() as changed:
        assert not changed


def test_other_c_library(monkeypatch):
    """Another C library than glibc (musl, macOS): nothing fixed, nothing changed."""
    monkeypatch.setattr(allocator, "glibc", lambda: None)
    monkeypatch.setattr(allocator, "start_environment",
                        lambda: {"MALLOC_TRIM_THRESHOLD_": "65536"})
    assert allocator.fixed_trim_threshold() is None
    with allocator.glibc_thresholds() as changed:
        assert not changed
