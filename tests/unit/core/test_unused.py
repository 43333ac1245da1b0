"""Modules pcmapq never uses are left out of its own processes, and Open3D loads without them."""

from __future__ import annotations

import subprocess
import sys
from importlib.machinery import PathFinder

import pytest

from pcmapq.core.unused import UNUSED

CHECK = """
import sys
from pcmapq.core.unused import leave_out_unused
leave_out_unused()
import open3d
print(open3d.geometry.PointCloud().is_empty(), sorted(n for n in {names!r} if sys.modules.get(n)))
"""


def test_open3d_loads_without_the_unused_modules():
    if not any(PathFinder.find_spec(name) for name in UNUSED):
        pytest.skip("none of the unused modules is installed here: there is nothing to leave out")
    got = subprocess.run([sys.executable, "-c", CHECK.format(names=UNUSED)], capture_output=True,
                         text=True, timeout=120)
    assert got.returncode == 0, got.stderr
    assert got.stdout.split() == ["True", "[]"], got.stdout
