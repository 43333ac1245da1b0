"""MapEval's AWD on KITTI 00 (../shared/data/kitti00): maps whose scans drift more in pitch lie
further from the map of the reference poses, step by step (the frame given; after a 3D
registration and MapEval's own arithmetic: ``python -m bench.bench_map_gaussians --ladder``)."""

from __future__ import annotations

import pytest

from pcmapq.metrics.map_gaussians import map_gaussians
from testkit.kitti import pitch_ladder

STEPS = (0.05, 0.1, 0.2, 0.4)


def test_awd_rises_with_each_step_of_pitch_drift():
    truth, maps = pitch_ladder(STEPS)
    same = map_gaussians(truth, truth)
    assert (same.awd_m, same.scs) == (0.0, 0.0) and same.voxels > 500
    awd = [map_gaussians(maps[step], truth).awd_m for step in STEPS]
    assert all(a < b for a, b in zip([0.0, *awd], awd, strict=False))
    assert awd[0] > 0.1 and awd[-1] == pytest.approx(0.73, abs=0.05)
