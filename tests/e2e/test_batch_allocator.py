"""A batch row in a process started with Dask's worker environment
(``MALLOC_TRIM_THRESHOLD_=65536``) allocates as a plain process does: a large array freed and
allocated again reuses its pages within :func:`pcmapq.batch.allocator.glibc_thresholds`
instead of faulting them in anew, and the environment's thresholds are back after it."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from pcmapq.batch import allocator

#: 200 arrays of 2 MiB, allocated and freed in turn: the minor page faults it takes, printed
#: outside, within and after glibc_thresholds.
CHILD = """
import resource
import numpy as np
from pcmapq.batch.allocator import glibc_thresholds

def faults():
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(200):
        np.ones(1 << 18).sum()
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

outside = faults()
with glibc_thresholds() as changed:
    within = faults()
print(changed, outside, within, faults())
"""


@pytest.mark.skipif(allocator.glibc() is None, reason="glibc's allocator only")
def test_rows_reuse_pages_in_dasks_environment():
    env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
    got = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True,
                         env={**env, "MALLOC_TRIM_THRESHOLD_": "65536"}, timeout=120)
    assert got.returncode == 0, got.stderr
    changed, outside, within, after = got.stdout.split()
    pages = 200 * (2 << 20) // os.sysconf("SC_PAGE_SIZE")
    assert changed == "True"
    assert int(outside) > pages // 2  # every array faulted in anew
    assert int(within) < pages // 20  # its pages reused
    assert int(after) > pages // 2  # the environment's thresholds again
