"""Planes of a 3D cloud and the lines where they meet, on clouds of known planes."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.features.lines3d import plane_lines
from pcmapq.features.planes3d import PlaneParams, find_planes
from testkit import building3d as b


def corner(gap: float = 0.0, seed: int = 0) -> np.ndarray:
    """A floor 4 x 3 m at z = 0 (x in [0, 4]) and a wall 3 m wide, 2.5 m high at x = 4 + gap,
    400 points a square metre, 1 cm noise."""
    faces = [b.Face("floor", 2, 0.0, (0.0, 0.0), (4.0, 3.0)),
             b.Face("wall", 0, 4.0 + gap, (0.0, 0.0), (3.0, 2.5))]
    return b.cloud(faces, seed=seed)


def test_a_floor_and_a_wall_are_two_planes_of_known_normal_offset_and_extent():
    planes = find_planes(corner())
    assert len(planes) == 2
    floor, wall = (0, 1) if planes.normal[0, 2] > 0.9 else (1, 0)
    np.testing.assert_allclose(planes.normal[floor], [0, 0, 1], atol=0.01)
    np.testing.assert_allclose(planes.normal[wall], [1, 0, 0], atol=0.01)
    assert planes.offset[floor] == pytest.approx(0.0, abs=0.01)
    assert planes.offset[wall] == pytest.approx(4.0, abs=0.01)
    np.testing.assert_allclose(planes.extent[floor], [4.0, 3.0], atol=0.15)
    np.testing.assert_allclose(planes.extent[wall], [3.0, 2.5], atol=0.15)
    np.testing.assert_allclose(planes.centroid[wall], [4.0, 1.5, 1.25], atol=0.1)
    assert planes.area[floor] == pytest.approx(12.0, rel=0.15)
    assert planes.area[wall] == pytest.approx(7.5, rel=0.15)
    # the rectangle's corners lie in the plane, its first side the longer
    np.testing.assert_allclose(planes.corners[wall] @ planes.normal[wall], 4.0, atol=0.02)
    side = np.linalg.norm(planes.corners[:, 1] - planes.corners[:, 0], axis=1)
    np.testing.assert_allclose(side, planes.extent[:, 0])


def test_planes_below_the_least_area_or_points_are_left_out():
    assert len(find_planes(corner(), PlaneParams(min_area=8.0))) == 1  # the wall is 7.5 m^2
    assert len(find_planes(corner(), PlaneParams(min_points=2000))) == 0
    assert len(find_planes(np.zeros((10, 3)))) == 0


def test_the_planes_are_the_same_from_run_to_run_and_whatever_the_order_of_the_points():
    pts = corner()
    first, again = find_planes(pts), find_planes(pts)
    shuffled = find_planes(pts[np.random.default_rng(1).permutation(len(pts))])
    for field in ("normal", "offset", "centroid", "corners", "extent", "area", "points"):
        np.testing.assert_array_equal(getattr(first, field), getattr(again, field))
        # the voxels' centroids sum their points in another order: the last bits differ
        np.testing.assert_allclose(getattr(first, field), getattr(shuffled, field),
                                   atol=1e-9)


@pytest.mark.parametrize(("gap", "margin", "lines"), [(0.0, 0.2, 1), (0.5, 0.2, 0),
                                                     (0.5, 0.6, 1)])
def test_a_floor_and_a_wall_meet_in_a_line_where_their_extents_touch(gap, margin, lines):
    found = plane_lines(find_planes(corner(gap)), margin)
    assert len(found) == lines
    if lines:
        np.testing.assert_allclose(found.direction[0], [0, 1, 0], atol=0.01)
        np.testing.assert_allclose(found.point[0], [4.0 + gap, 1.5, 0.0], atol=0.1)
        assert found.length[0] == pytest.approx(3.0 + 2 * margin, abs=0.2)


def test_parallel_planes_and_short_lines_are_no_lines():
    faces = [b.Face("low", 2, 0.0, (0.0, 0.0), (4.0, 3.0)),
             b.Face("high", 2, 0.4, (4.0, 0.0), (8.0, 3.0))]
    assert len(plane_lines(find_planes(b.cloud(faces)), 0.5)) == 0
    assert len(plane_lines(find_planes(corner()), 0.2, min_length=5.0)) == 0


def test_the_building_has_its_eighteen_planes():
    """12 faces of two rooms, 5 of the box in A; of B's low box only its top (its sides are
    0.45 m^2)."""
    planes = find_planes(b.cloud(b.faces(), seed=1))
    assert len(planes) == 18
    assert (planes.area >= 1.0).all()


def test_one_line_of_several_pieces_lies_on_its_longest_piece():
    """A wall's foot on a floor 5 cm up, and on a sliver of floor at 0 that touches the wall's
    end only within the margin, the sliver's pair first: one line, the union of both pieces,
    at the floor's height (the sliver's would say the floor did not rise)."""
    planes = b.planes_of([b.Face("wall", 1, 0.0, (0.0, 0.0), (6.0, 2.5)),
                          b.Face("sliver", 2, 0.0, (6.1, 0.0), (7.5, 3.0)),
                          b.Face("floor", 2, 0.05, (0.0, 0.0), (6.0, 3.0))])
    found = plane_lines(planes, 0.2)
    assert len(found) == 1
    np.testing.assert_allclose(found.point[0], [3.0, 0.0, 0.05], atol=1e-9)
    assert found.length[0] == pytest.approx(6.4)  # from -0.2 to 6.2: both grown by the margin


def test_a_large_cloud_is_worked_on_a_block_at_a_time(monkeypatch):
    """A float32 cloud of 0.9 M points (a file mapped into memory): reduced in chunks and its
    per-point work done ROWS points at a time, it gives the planes of one block bit for bit,
    in less memory than a float64 copy of the cloud (none is made)."""
    import tracemalloc

    from pcmapq.core import voxel_table
    from pcmapq.features import planes3d

    rng = np.random.default_rng(3)
    cloud = np.vstack([b.sample(f, rng, density=4000.0) for f in b.faces()])
    cloud = (cloud + rng.normal(0.0, 0.01, cloud.shape)).astype(np.float32)
    whole = find_planes(cloud)  # its reduced points in one block
    monkeypatch.setattr(planes3d, "ROWS", 4096)
    monkeypatch.setattr(voxel_table, "CHUNK", 4096)
    tracemalloc.start()
    try:
        blocks = find_planes(cloud)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(blocks) == len(whole) == 18
    for name in ("normal", "offset", "centroid", "corners", "extent", "area", "points"):
        assert np.array_equal(getattr(blocks, name), getattr(whole, name))
    assert peak < 2 * cloud.nbytes
