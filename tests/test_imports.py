"""The scoring core loads no heavy package: Open3D, KISS-ICP and matplotlib are imported inside
the modules that use them, when they run."""

from __future__ import annotations

import subprocess
import sys

import pytest

HEAVY = ("open3d", "kiss_icp", "matplotlib")
CORE = ("pcmapq.settings", "pcmapq.match", "pcmapq.metrics.distances", "pcmapq.results.result",
        "pcmapq.features", "pcmapq.io", "pcmapq.align", "pcmapq.align.params")


@pytest.mark.parametrize("module", CORE)
def test_core_module_loads_no_heavy_package(module):
    code = (f"import sys, {module}; "
            f"print(','.join(h for h in {HEAVY!r} if h in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "", f"importing {module} loads {out}"


def test_the_check_sees_a_heavy_import():
    """The probe itself works: the 3D global registration module does load Open3D."""
    code = "import sys, pcmapq.align.features3d; print('open3d' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "True"
