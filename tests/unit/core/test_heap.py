"""The heap's free pages handed back to the system (glibc's malloc_trim)."""

from __future__ import annotations

import pytest

from pcmapq.core import heap


def resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


@pytest.mark.skipif(heap.glibc() is None, reason="glibc's allocator only")
def test_the_free_pages_of_the_heap_go_back_to_the_system():
    """50 MB of blocks below the mmap threshold, freed beneath one still held (so that glibc
    cannot trim the heap's top by itself), stay resident until released."""
    blocks = [bytearray(100_000) for _ in range(500)]
    held = bytearray(100_000)
    del blocks
    before = resident_bytes()
    assert heap.release_free_memory()
    assert before - resident_bytes() > 40e6
    del held
