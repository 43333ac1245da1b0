"""Inputs whose extent looks wrong (a copy or an outlier far away, millimetres, a resolution not in
metres, one straight wall) are found with a hint that says what looks wrong and how to fix it
(pcmapq.io.extent); crops keep the part that matters; every cloud loader checks the points its
file declares against the memory limit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import open3d as o3d
import pytest

from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.evaluation.inputs import check_structure
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.io.extent import MAX_SPAN, check_span, crop, hint, main_group
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN
from pcmapq.settings.table import OptionError, parse_box


def _box(points: np.ndarray) -> np.ndarray:
    return np.array([*points[:, :2].min(axis=0), *points[:, :2].max(axis=0)])


def test_main_group_boxes_the_points_near_each_other():
    rng = np.random.default_rng(1)
    room = rng.uniform([0, 0], [30, 20], (5000, 2))
    copy = room + [20_000.0, 0.0]
    box = main_group(np.vstack([room, room, copy]))
    assert box is not None
    lo, hi = [-1.1, -1.1, 30.0, 20.0], [0.0, 0.0, 31.1, 21.1]  # the room grown by up to 1.1 m
    assert np.all((np.array(box) >= lo) & (np.array(box) <= hi)), box
    assert main_group(room) is None
    # a large map with no gap (a 400 m campus) is one group
    assert main_group(rng.uniform([0, 0], [400, 300], (20000, 2))) is None


def test_hint_says_which_points_are_far_and_the_crop_that_keeps_the_rest(scan_points):
    far = np.vstack([scan_points, [[5000.0, 3.0, 1.0]]])
    text = hint(PointMap(Path("m.npy"), far, True), "--map-crop")
    assert text.startswith(f"1 of its {len(far):,} points lies far from the others")
    box = text.split("--map-crop ")[1].split(" keeps")[0]
    lo_hi = np.array([float(v) for v in box.split(",")])
    inside = _box(scan_points)
    assert np.all(lo_hi[:2] <= inside[:2]) and np.all(lo_hi[2:] >= inside[2:])
    assert np.all(lo_hi[:2] >= inside[:2] - 1.2) and np.all(lo_hi[2:] <= inside[2:] + 1.2)


def test_hint_names_millimetres_and_resolutions_that_are_not_metres(scan_points):
    mm = PointMap(Path("mm.ply"), scan_points * 1000.0, True)
    assert "millimetres" in hint(mm, "--truth-crop")
    assert "cells are 1e-05 m wide" in hint(PointMap(Path("c.ply"), scan_points, True),
                                            "--truth-crop", cell=1e-5)
    state = np.zeros((10, 10), np.int8)
    image = OccupancyMap(Path("t.yaml"), MetricGrid(1e9, (0.0, 0.0, 0.0), (10, 10)), state)
    assert "cells are 1e+09 m wide" in hint(image, "--truth-crop")
    assert hint(PointMap(Path("s.ply"), scan_points, True), "--map-crop") == ""


def test_an_input_wider_than_the_limit_is_refused_saying_why(scan_points):
    far = PointMap(Path("m.npy"), np.vstack([scan_points, [[1e300, 0.0, 1.0]]]), True)
    with pytest.raises(InputError, match=f"m.npy: wider than {MAX_SPAN / 1000:.0f} km.*--map-crop"):
        check_span(far, "--map-crop")
    check_span(PointMap(Path("s.ply"), scan_points, True), "--map-crop")


def test_crop_of_an_image_keeps_the_cells_whose_centres_lie_in_the_box():
    grid = MetricGrid(0.1, (-1.0, -2.0, 0.0), (40, 60))
    state = np.random.default_rng(2).choice([OCCUPIED, FREE, UNKNOWN], grid.shape).astype(np.int8)
    cut = crop(OccupancyMap(Path("m.png"), grid, state), (0.0, 0.0, 2.0, 1.0), "--map-crop")
    centres = grid.cell_centres(np.ones(grid.shape, bool)).reshape(*grid.shape, 2)
    inside = ((centres[..., 0] >= 0) & (centres[..., 0] <= 2) & (centres[..., 1] >= 0)
              & (centres[..., 1] <= 1))
    assert cut.state.shape == (10, 20)
    np.testing.assert_array_equal(cut.state.ravel(), state[inside])
    kept = cut.grid.cell_centres(np.ones(cut.state.shape, bool))
    np.testing.assert_allclose(kept, centres[inside], atol=1e-9)


def test_crop_of_a_turned_image_makes_cells_outside_the_box_unknown():
    grid = MetricGrid(0.1, (0.0, 0.0, np.radians(30.0)), (50, 50))
    state = np.full(grid.shape, OCCUPIED, np.int8)
    cut = crop(OccupancyMap(Path("m.png"), grid, state), (0.0, 1.0, 2.0, 3.0), "--map-crop")
    centres = cut.grid.cell_centres(cut.state == OCCUPIED)
    assert len(centres) > 0 and (cut.state == UNKNOWN).any()
    assert np.all((centres >= [0.0, 1.0]) & (centres <= [2.0, 3.0]))


def test_crop_of_a_cloud_and_a_crop_that_keeps_nothing(scan_points):
    cloud = PointMap(Path("s.ply"), scan_points, True)
    cut = crop(cloud, (0.0, 0.0, 5.0, 5.0), "--map-crop")
    xy = scan_points[:, :2]
    assert len(cut.points) == int(np.all((xy >= 0) & (xy <= 5), axis=1).sum())
    with pytest.raises(InputError, match="s.ply: --map-crop 100.0,100.0,101.0,101.0 keeps none"):
        crop(cloud, (100.0, 100.0, 101.0, 101.0), "--map-crop")


def test_crop_of_a_cloud_keeps_the_scans_of_the_points_it_keeps(scan_points):
    scan = np.arange(len(scan_points), dtype=float)
    cut = crop(PointMap(Path("s.ply"), scan_points, True, scan=scan), (0.0, 0.0, 5.0, 5.0),
               "--map-crop")
    kept = np.all((scan_points[:, :2] >= 0) & (scan_points[:, :2] <= 5), axis=1)
    np.testing.assert_array_equal(cut.scan, scan[kept])


def test_one_straight_wall_has_nothing_to_align_and_an_l_has():
    x = np.linspace(0.0, 10.0, 2000)
    wall = np.column_stack([x, 0.02 * np.sin(x)])
    with pytest.raises(EvaluationError, match="one straight line .10.0 m long"):
        check_structure(Path("line.npy"), wall)
    corner = np.vstack([wall, np.column_stack([np.zeros(500), np.linspace(0, 3, 500)])])
    check_structure(Path("corner.npy"), corner)


@pytest.mark.parametrize("text", ["0,0,1", "0,0,1,x", "1,0,0,1", "0,0,1,nan", "0,1,1,1"])
def test_a_bad_box_is_a_usage_error(text):
    with pytest.raises(OptionError, match="expected a box x0,y0,x1,y1") as err:
        parse_box(text, "--map-crop")
    assert err.value.option == "--map-crop"


@pytest.mark.parametrize("name", ["b.ply", "a.ply", "b.pcd", "a.pcd", "c.npy", "k.bin"])
def test_every_cloud_loader_checks_the_points_declared_against_the_limit(tmp_path, name):
    """A limit that holds half of what the declared points need refuses the file before it is
    read; one that holds them all loads it."""
    from pcmapq.core import memory

    n = 20_000
    points = np.random.default_rng(3).uniform(0, 5, (n, 3))
    path = tmp_path / name
    if name.endswith(".npy"):
        np.save(path, points)
    elif name.endswith(".bin"):
        np.column_stack([points, np.zeros(n)]).astype("<f4").tofile(path)
    else:
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
        assert o3d.io.write_point_cloud(str(path), cloud, write_ascii=name.startswith("a"))
    need = memory.needed_bytes(0, 0, 0.0, n)
    with pytest.raises(InputError, match=f"{name}.*needs about"):
        load_map(path, memory_limit=need - 50 * n)
    assert len(load_map(path, memory_limit=need).points) == n


def test_far_points_split_along_x_then_y_keep_a_group() -> None:
    """Found by the cloud property: two points 1.1e8 m apart in x and 4.1e7 m in y. Split along
    each axis on its own, x kept the first point and y the second, so the main group was empty
    and its box a ValueError (a traceback where a one-line 'wider than 100 km' belongs)."""
    from pcmapq.io.extent import main_group

    xy = np.array([[-47677573.15, -40301771.32], [62845148.12, -81616811.57]])
    box = main_group(xy)
    assert box is not None
    x0, y0, x1, y1 = box
    inside = (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
    assert inside.sum() == 1
