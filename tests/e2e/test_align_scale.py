"""Alignment of maps of unknown scale: scale, rotation and translation with no initial guess."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align import AlignParams, align
from pcmapq.align.point_to_line import LineTarget, refine_point_to_line
from pcmapq.align.similarity_icp import fit_similarity
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import voxel_centroids
from testkit import synth
from testkit.alignment import HEIGHT, PLAN, WIDTH, inside, plan_scan, plan_truth


@pytest.fixture(scope="module")
def truth() -> np.ndarray:
    """The plan's walls as points 5 cm apart, plan frame, metres."""
    return plan_truth()


@pytest.fixture(scope="module")
def scan() -> np.ndarray:
    """The same walls sampled again with 1.5 cm noise, in the plan frame."""
    return plan_scan()


def similarity(scale: float, yaw_deg: float, tx: float, ty: float) -> Similarity2D:
    return Similarity2D(tx, ty, float(np.radians(yaw_deg)), scale)


def errors(expected: Similarity2D, got: Similarity2D) -> tuple[float, float, float]:
    """(relative scale error, yaw error in degrees, translation error in truth units)."""
    dyaw = abs((np.degrees(got.yaw - expected.yaw) + 180.0) % 360.0 - 180.0)
    return (abs(got.scale / expected.scale - 1.0), float(dyaw),
            float(np.hypot(got.tx - expected.tx, got.ty - expected.ty)))


@pytest.fixture(scope="module")
def aligned(truth, scan):
    """``aligned(t_true, box=None)``: the scan (its part inside ``box``) seen through
    ``t_true``, aligned with scale, once for every test that reads it."""
    done: dict = {}

    def run(t_true: Similarity2D, box: tuple | None = None):
        if (t_true, box) not in done:
            part = scan if box is None else inside(scan, box)
            done[t_true, box] = align(t_true.inverse().apply(part), truth, scale=True)
        return done[t_true, box]

    return run


@pytest.mark.parametrize(("scale", "yaw", "tx", "ty"), [
    (0.5, 120, 3.0, -4.0), (0.8, -75, -6.0, 2.0), (1.3, 30, 10.0, 5.0), (2.5, 200, -3.0, 8.0)])
def test_full_map_of_unknown_scale(aligned, scale, yaw, tx, ty):
    t_true = similarity(scale, yaw, tx, ty)
    result = aligned(t_true)
    ds, dyaw, dxy = errors(t_true, result.transform)
    assert ds < 0.01 and dyaw < 0.5 and dxy < 0.1
    assert result.fitness > 0.9 and result.rmse_m < 0.05 and result.method == "similarity+icp"


@pytest.mark.parametrize(("box", "scale", "yaw", "tx", "ty"), [
    ((-1.0, -1.0, 0.5 * WIDTH + 0.5, 17.0), 0.8, 120, 4.0, 4.0),          # left half
    ((-1.0, -1.0, 0.75 * WIDTH, 0.75 * HEIGHT), 2.5, -75, -5.0, 3.0),      # 56 % corner
    ((0.38 * WIDTH, 0.33 * HEIGHT, 25.0, 17.0), 1.3, 45, 1.0, 1.0),        # top-right 42 %
])
def test_partial_map_of_unknown_scale(aligned, box, scale, yaw, tx, ty):
    t_true = similarity(scale, yaw, tx, ty)
    result = aligned(t_true, box)
    ds, dyaw, dxy = errors(t_true, result.transform)
    assert ds < 0.01 and dyaw < 0.5 and dxy < 0.1
    assert result.fitness > 0.9


def test_plan_picture_in_pixels(truth):
    """A plan drawn as an image and given in pixels (the map's 'unit' is its 4 cm cell)."""
    t_true = similarity(0.04, -75, 12.0, -5.0)
    segments = synth.transform_segments(PLAN, t_true.inverse())
    grid = synth.plan_grid(segments, 1.0, margin=20.0)  # one pixel = one map unit
    pixels = grid.cell_centres(synth.render(segments, grid, thickness=4.0) == synth.OCCUPIED)
    result = align(pixels, truth, AlignParams(scale_range=(0.01, 1.0)), scale=True)
    ds, dyaw, dxy = errors(t_true, result.transform)
    assert ds < 0.01 and dyaw < 0.5 and dxy < 0.1


def test_rigid_map_keeps_scale_one(truth, scan):
    t_true = similarity(1.0, 15, 5.0, -3.0)
    result = align(t_true.inverse().apply(scan), truth, scale=True)
    ds, dyaw, dxy = errors(t_true, result.transform)
    assert ds < 0.002 and dyaw < 0.5 and dxy < 0.1


def test_other_building_scores_low(truth, aligned):
    other = synth.wall_points(synth.building_plan(7, 18.0, 20.0), spacing=0.05, noise=0.015,
                              seed=3)
    t_true = similarity(1.3, 30, 10.0, 5.0)  # a pose of test_full_map_of_unknown_scale
    wrong = align(t_true.inverse().apply(other), truth, scale=True)
    assert wrong.fitness < 0.6 < 0.9 < aligned(t_true).fitness


def test_init_and_no_refine(truth, scan):
    t_true = similarity(0.8, 172, 35.0, 40.0)
    map_xy = t_true.inverse().apply(scan)
    init = Similarity2D(0.3, -0.2, 0.0, 1.02).compose(t_true)
    result = align(map_xy, truth, scale=True, init=init)
    ds, dyaw, dxy = errors(t_true, result.transform)
    assert result.method == "init+icp" and ds < 0.002 and dyaw < 0.2 and dxy < 0.05
    kept = align(map_xy, truth, scale=True, init=t_true, refine=False)
    assert kept.method == "init" and kept.transform == t_true and kept.fitness > 0.99


def test_deterministic_and_empty(truth, scan, aligned):
    t_true, box = similarity(2.5, -75, -5.0, 3.0), (-1.0, -1.0, 0.75 * WIDTH, 0.75 * HEIGHT)
    map_xy = t_true.inverse().apply(inside(scan, box))  # a case of test_partial_map_of_...
    assert align(map_xy, truth, scale=True) == aligned(t_true, box)
    empty = align(np.empty((0, 2)), truth, scale=True)
    assert empty.fitness == 0.0 and empty.method == "none"


def test_fit_similarity_is_exact():
    t_true = similarity(0.37, 120, 3.0, -2.0)
    points = np.random.default_rng(0).normal(size=(50, 2))
    got = fit_similarity(points, t_true.apply(points))
    assert errors(t_true, got) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)


def test_point_to_line_refines_scale(truth):
    """From 3 % off in scale, the point-to-line stage with scale lands on the truth."""
    xy = voxel_centroids(truth, 0.05)
    got = refine_point_to_line(xy, LineTarget(xy), Similarity2D(0.1, 0.0, 0.0, 1.03),
                               with_scale=True)
    assert errors(Similarity2D(), got) == pytest.approx((0.0, 0.0, 0.0), abs=1e-4)
