"""The planes' own fit on exact planes of the synthetic building: a known pull of the whole map
undone whatever a few moved planes say, a direction held by one plane left alone, a motion
beyond the reach found but not applied."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.features.planes3d import Planes
from pcmapq.match.plane_fit import moved as moved_planes
from pcmapq.match.plane_fit import plane_fit, rotation
from testkit import building3d as b


def pull(angle_deg: float, lift: float) -> np.ndarray:
    """A rigid motion (4x4): a pitch of ``angle_deg`` about the y axis, then ``lift`` metres
    up."""
    m = np.eye(4)
    m[:3, :3] = rotation(np.radians([0.0, angle_deg, 0.0]))
    m[2, 3] = lift
    return m


def distances(truth: Planes, map_: Planes) -> np.ndarray:
    """Each map plane's RMS corner distance from its truth plane (same order), metres."""
    d = np.einsum("kj,kcj->kc", truth.normal, map_.corners) - truth.offset[:, None]
    return np.sqrt(np.mean(d ** 2, axis=1))


def test_a_pull_of_the_whole_map_is_undone_whatever_the_moved_planes_say():
    truth = b.planes_of(b.faces())
    changed = b.changed(b.faces(b_end=b.B_END + 0.3), {"A.floor": 0.05})
    pulled = moved_planes(b.planes_of(changed), pull(0.16, -0.03))
    every = np.arange(len(truth))
    fit = plane_fit(truth, pulled, every, every, reach=0.15)
    assert fit.applied and fit.pairs == len(truth) and fit.held == len(truth) - 2
    np.testing.assert_allclose(fit.matrix @ pull(0.16, -0.03), np.eye(4), atol=1e-9)
    assert fit.angle == pytest.approx(0.16, abs=1e-6)
    left = distances(truth, moved_planes(pulled, fit.matrix))
    names = [f.name for f in changed]
    assert left[names.index("A.floor")] == pytest.approx(0.05, abs=1e-9)
    assert left[names.index("B.wall.x1")] == pytest.approx(0.3, abs=1e-9)
    assert np.delete(left, [names.index("A.floor"), names.index("B.wall.x1")]).max() < 1e-9


def test_a_plane_alone_in_its_direction_keeps_its_displacement():
    """Room A without its ceiling nor its box's top: the floor alone says where up is, so its
    0.05 m rise is not fitted away (an L1 fit over every direction would zero it)."""
    parts = [f for f in b.faces() if f.name.startswith("A.")
             and f.name not in ("A.ceiling", "A.box.top")]
    truth = b.planes_of(parts)
    raised = b.planes_of(b.changed(parts, {"A.floor": 0.05}))
    every = np.arange(len(truth))
    fit = plane_fit(truth, raised, every, every)
    # the directions the floor shares with the walls (its tilts) leak a few micrometres
    np.testing.assert_allclose(fit.matrix, np.eye(4), atol=1e-4)
    floor = [f.name for f in parts].index("A.floor")
    assert distances(truth, moved_planes(raised, fit.matrix))[floor] == \
        pytest.approx(0.05, abs=1e-4)


def test_a_motion_beyond_the_reach_is_found_and_not_applied():
    """A map turned 2 degrees: its corners move up to 0.3 m, beyond a 0.15 m reach."""
    truth = b.planes_of(b.faces())
    every = np.arange(len(truth))
    fit = plane_fit(truth, moved_planes(truth, pull(2.0, 0.0)), every, every, reach=0.15)
    assert not fit.applied and fit.largest_move > 0.15
    np.testing.assert_array_equal(fit.matrix, np.eye(4))
    assert fit.angle == pytest.approx(2.0, abs=1e-6)
    assert plane_fit(truth, truth, every[:0], every[:0]).pairs == 0


def test_planes_moved_stay_planes():
    planes = b.planes_of(b.faces())
    motion = pull(3.0, 0.2)
    motion[:3, :3] = rotation(np.radians([1.0, -2.0, 30.0])) @ motion[:3, :3]
    got = moved_planes(planes, motion)
    np.testing.assert_allclose(np.einsum("kj,kcj->kc", got.normal, got.corners),
                               np.repeat(got.offset[:, None], 4, axis=1), atol=1e-9)
    big = np.take_along_axis(got.normal, np.abs(got.normal).argmax(axis=1)[:, None], axis=1)
    assert (big > 0).all()
    np.testing.assert_array_equal(got.extent, planes.extent)
