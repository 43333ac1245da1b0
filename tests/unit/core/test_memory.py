"""The memory guard's estimate: it grows with each size as measured, and the default limit is
three quarters of the machine."""

from __future__ import annotations

import pytest

from pcmapq.core import memory
from pcmapq.core.errors import InputError


def test_estimate_grows_with_each_size():
    base = memory.needed_bytes(0, 0, 0.0, 0)
    assert base == memory.BASE
    # an 8000 x 8000 grid of 0.05 m cells, its image and the map's: about 9.2 GB, above the
    # largest peak measured on the campus pair (8.1 GB, docs/benchmarks.md "Memory guard")
    cells = 8000 * 8000
    need = memory.needed_bytes(2 * cells, cells, cells * 0.05**2, 0)
    assert 8.2e9 < need < 10e9
    # a 1.9 mm grid of the same cells covers 700 times less ground: far fewer working cells
    assert memory.needed_bytes(2 * cells, cells, cells * 0.0019**2, 0) < need / 2
    assert memory.needed_bytes(0, 0, 0.0, 10_000_000) == base + 1e9


def test_guard():
    memory.guard(10**9, 2 * 10**9, "x")  # under the limit: nothing
    with pytest.raises(InputError, match=r"^a.ply: needs about 3.0 GB .* limit of 2.0 GB"):
        memory.guard(3 * 10**9, 2 * 10**9, "a.ply")
    assert memory.default_limit() == int(0.75 * memory.machine_bytes())
