"""A real SLAM map, stretch by stretch (testkit.realdata.kiss_run; docs/validation.md's
section, ``python -m bench.validation --only kiss_run``): KISS-ICP's map of KITTI 00's first 20
scans, built by ``pcmapq map`` so that its points carry their scans, against the reference map;
each stretch of its run checked against KISS-ICP's own pose error. About 20 s."""

from __future__ import annotations

import numpy as np

from testkit.paths import shared
from testkit.realdata.kiss_run import measure


def test_each_stretch_shows_the_pose_error_of_its_scans():
    """Five stretches of 4 scans, all held; each one's offset within 0.2 m and its roll, pitch
    and yaw within 0.3 degrees of the mean error KISS-ICP's trajectory gives its scans
    (measured: 0.13 m, 0.21 degrees); the first stretch, off by more than a metre and a
    degree of yaw by the trajectory, is the one the map reports most off, the last within
    0.1 m."""
    stretches = measure(shared("kitti00")).stretches
    assert [s.scans for s in stretches] == [(k, k + 3) for k in range(0, 20, 4)]
    assert all(s.held for s in stretches)
    assert max(s.offset_error_m for s in stretches) < 0.2
    assert max(s.turn_error_deg for s in stretches) < 0.3
    first = stretches[0]
    assert np.linalg.norm(first.expected_m) > 1.0 and abs(first.expected_deg[2]) > 1.0
    reported = [np.linalg.norm(s.reported_m) for s in stretches]
    assert int(np.argmax(reported)) == 0 and reported[-1] < 0.1
