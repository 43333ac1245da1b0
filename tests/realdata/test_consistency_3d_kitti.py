"""The 3D consistency map on real LiDAR data: KITTI 00's first 20 scans (12 m of range each)
at poses whose pitch drifts by 0.2 degrees a step, against the map at the reference poses
(testkit.realdata.bends3d; the whole ladder is docs/validation.md's section, ``python -m
bench.validation --only consistency_3d``). About 20 s."""

from __future__ import annotations

from testkit.paths import shared
from testkit.realdata.bends3d import WITHIN_M, WITHIN_SHARE, measure


def test_a_pitch_drift_shows_where_the_run_ends():
    """The held region where the drift leaves the largest vertical error is the one with the
    largest reported |dz|, reported within 0.05 m + 10 % of the injected offset of the error
    its points carry; every held region within 5 cm of its own."""
    rung = measure(shared("kitti00"), "pitch", 0.2)
    assert rung.injected_m < -0.5 and rung.expected_m < -0.3
    assert rung.same_region
    assert abs(rung.reported_m - rung.expected_m) <= WITHIN_M + WITHIN_SHARE * abs(rung.injected_m)
    assert rung.max_error_m < 0.05 and rung.held >= 8
