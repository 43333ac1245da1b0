"""The paper's method on 3D structures: a synthetic building (two rooms, furniture, 1 cm noise)
against copies of it with known changes, both already in the truth frame."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.features.planes3d import PlaneParams, find_planes
from pcmapq.match.structures import compare_structures, match_structures
from testkit import building3d as b

#: The thresholds of the defaults: 5 degrees, 0.5 m; lines where extents touch within 0.2 m,
#: at least 1.5 m long.
ANGLE, OFFSET, MARGIN, LENGTH = 5.0, 0.5, 0.2, 1.5


@pytest.fixture(scope="module")
def truth() -> np.ndarray:
    return b.cloud(b.faces(), seed=1)


def compared(truth: np.ndarray, map_: np.ndarray):
    return compare_structures(truth, map_, PlaneParams(), MARGIN, LENGTH, ANGLE, OFFSET)


def plane_at(planes, point: tuple[float, float, float], normal_axis: int) -> int:
    """The plane of ``planes`` through ``point`` (within 0.1 m) whose normal is along
    ``normal_axis``, and inside whose rectangle (grown 0.2 m) the point lies."""
    hits = []
    for k in range(len(planes)):
        if abs(planes.normal[k, normal_axis]) < 0.99:
            continue
        if abs(planes.normal[k] @ np.asarray(point) - planes.offset[k]) > 0.1:
            continue
        uv = planes.axes[k] @ (np.asarray(point) - planes.centre[k])
        if (np.abs(uv) <= planes.extent[k] / 2 + 0.2).all():
            hits.append(k)
    assert len(hits) == 1, hits
    return hits[0]


def test_identical_clouds_match_every_structure(truth):
    found = compared(truth, truth)
    for name in ("planes", "plane_lines"):
        m = found.detectors[name].matching
        assert m.quality == m.precision == m.f1 == 1.0
        assert m.truth_structures == m.map_structures == m.matched > 0
        np.testing.assert_allclose(m.displacement, 0.0, atol=1e-9)
    assert found.detectors["planes"].matching.truth_structures == 18


def test_a_wall_moved_and_a_floor_raised_are_the_two_displaced_planes(truth):
    """Room B's far wall 0.3 m further along its normal (+x, the room longer), room A's floor
    0.05 m higher (+z), another draw of the noise: exactly those two planes are displaced, by
    their amounts and signs; every other plane is matched within 1 cm."""
    moved = b.cloud(b.changed(b.faces(b_end=b.B_END + 0.3), {"A.floor": 0.05}), seed=2)
    found = compared(truth, moved)
    planes = found.detectors["planes"]
    m = planes.matching
    assert m.quality == m.precision == 1.0
    wall = plane_at(planes.truth, (b.B_END, 2.5, 1.4), 0)
    floor = plane_at(planes.truth, (3.0, 4.0, 0.0), 2)
    disp = dict(zip(m.truth_idx.tolist(), m.displacement.tolist(), strict=True))
    assert disp.pop(wall) == pytest.approx(0.30, abs=0.02)
    assert disp.pop(floor) == pytest.approx(0.05, abs=0.01)
    assert max(abs(d) for d in disp.values()) < 0.01
    assert (m.angle < 1.0).all()
    # the lines at the wall's foot and head moved with it
    lines = found.detectors["plane_lines"].matching
    assert lines.quality == 1.0
    assert np.sum(np.abs(lines.displacement - 0.3) < 0.02) >= 2


def test_a_wall_removed_is_the_one_missing_plane(truth):
    gone = b.cloud(b.changed(b.faces(), removed=("A.wall.y0",)), seed=2)
    found = compared(truth, gone)
    planes = found.detectors["planes"]
    m = planes.matching
    n = m.truth_structures
    assert m.quality == pytest.approx((n - 1) / n) and m.precision == 1.0
    assert m.missing.tolist() == [plane_at(planes.truth, (3.0, 0.0, 1.4), 1)]
    assert len(m.extra) == 0
    assert found.detectors["plane_lines"].matching.quality < 1.0


def test_a_plane_beyond_the_thresholds_does_not_match(truth):
    """Room B's far wall 0.6 m further is too far along its normal (0.5 m): the truth's wall
    is missing and the map's extra."""
    found = compared(truth, b.cloud(b.faces(b_end=b.B_END + 0.6), seed=2))
    planes = found.detectors["planes"]
    m = planes.matching
    n = m.truth_structures
    assert (m.quality, m.precision) == (pytest.approx((n - 1) / n), pytest.approx((n - 1) / n))
    assert m.missing.tolist() == [plane_at(planes.truth, (b.B_END, 2.5, 1.4), 0)]
    assert m.extra.tolist() == [plane_at(planes.map, (b.B_END + 0.6, 2.5, 1.4), 0)]


def test_a_truth_without_structures_has_nothing_to_find(truth):
    planes = find_planes(truth)
    none = find_planes(np.zeros((0, 3)))
    m = match_structures("planes", none, planes, ANGLE, OFFSET)
    assert (m.quality, m.precision, m.f1) == (None, None, None)
    assert m.note("plane") == "the truth has no plane: nothing to find"
    empty = match_structures("planes", planes, none, ANGLE, OFFSET)
    assert (empty.quality, empty.precision, empty.f1) == (0.0, None, None)
    assert empty.note("plane") == "no map plane"


def test_the_structures_are_the_same_from_run_to_run(truth):
    moved = b.cloud(b.changed(b.faces(b_end=b.B_END + 0.3), {"A.floor": 0.05}), seed=2)
    b.assert_same_matches(compared(truth, moved), compared(truth, moved))


def test_the_truths_planes_found_beforehand_give_the_same_structures(truth):
    """An evaluation finds a 3D truth's planes while its map registers: the same planes, so
    the same matches, as when both clouds' planes are found together."""
    moved = b.cloud(b.changed(b.faces(b_end=b.B_END + 0.3), {"A.floor": 0.05}), seed=2)
    together = compared(truth, moved)
    before = compare_structures(truth, moved, PlaneParams(), MARGIN, LENGTH, ANGLE, OFFSET,
                                truth_planes=find_planes(truth, PlaneParams()))
    b.assert_same_matches(together, before)
