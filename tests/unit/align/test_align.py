"""2D alignment: global search + ICP on synthetic plans with known transforms."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align import Alignment, AlignParams, align, score
from pcmapq.align.coarse import coarse_search
from pcmapq.align.finalists import TIE_COVERAGE, TIE_FITNESS, refine_best
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import evenly, voxel_centroids
from testkit import synth
from testkit.alignment import HEIGHT, PLAN, WIDTH, inside
from testkit.poses import pose_error


def to_map_frame(points: np.ndarray, yaw_deg: float, tx: float, ty: float):
    """(T_true, points in a map frame such that T_true maps them back to the plan frame)."""
    t_true = Similarity2D(tx, ty, np.radians(yaw_deg))
    return t_true, t_true.inverse().apply(points)


@pytest.fixture(scope="module")
def aligned(truth, scan):
    """``aligned(yaw, tx, ty, box=None)``: (T_true, the scan (its part inside ``box``) seen
    through T_true and aligned), once for every test that reads it."""
    done: dict = {}

    def run(yaw: float, tx: float, ty: float, box: tuple | None = None):
        if (yaw, tx, ty, box) not in done:
            t_true, map_xy = to_map_frame(scan if box is None else inside(scan, box), yaw, tx, ty)
            done[yaw, tx, ty, box] = t_true, align(map_xy, truth)
        return done[yaw, tx, ty, box]

    return run


@pytest.mark.parametrize(("yaw", "tx", "ty"), [(15, 5.0, -3.0), (90, -20.0, 12.0),
                                               (172, 35.0, 40.0), (-47, -12.0, -30.0)])
def test_rigid_full_map(aligned, yaw, tx, ty):
    t_true, result = aligned(yaw, tx, ty)
    dxy, dyaw = pose_error(t_true, result.transform)
    assert dxy < 0.1 and dyaw < 0.5
    assert result.fitness > 0.9 and result.rmse_m < 0.05
    assert result.method == "coarse+icp" and result.tolerance_m == 0.2
    assert result.transform.scale == 1.0


@pytest.mark.parametrize(("box", "yaw", "tx", "ty"), [
    ((-1.0, -1.0, 0.5 * WIDTH, 17.0), 33, 8.0, -6.0),                             # left half
    ((0.42 * WIDTH, 0.42 * HEIGHT, 25.0, 17.0), -120, -15.0, 25.0),               # top-right third
    ((-1.0, -1.0, 0.775 * WIDTH, 0.775 * HEIGHT), 200, 22.0, 4.0),                 # 60 % corner
    ((-1.0, -1.0, 25.0, 0.3 * HEIGHT), 71, -3.0, -18.0),                           # bottom 30 %
])
def test_partial_map(aligned, box, yaw, tx, ty):
    t_true, result = aligned(yaw, tx, ty, box)
    dxy, dyaw = pose_error(t_true, result.transform)
    assert dxy < 0.1 and dyaw < 0.5
    assert result.fitness > 0.9


def test_partial_map_against_cluttered_truth(scan):
    """Boxes crowd the truth; the map's own part, not the densest region, must still win."""
    truth = synth.wall_points(synth.clutter(PLAN, 40, seed=4), spacing=0.05)
    t_true, map_xy = to_map_frame(inside(scan, (0.5 * WIDTH, -1.0, 25.0, 17.0)), 140, 30.0, 10.0)
    dxy, dyaw = pose_error(t_true, align(map_xy, truth).transform)
    assert dxy < 0.1 and dyaw < 0.5


def test_bent_map_still_aligns(truth):
    bent = synth.wall_points(synth.bend_segments(PLAN, 0.3), spacing=0.05, noise=0.015, seed=2)
    t_true, map_xy = to_map_frame(bent, 60, 10.0, 5.0)
    result = align(map_xy, truth)
    # The bend turns the far end by 7 degrees: most of the map fits, not all of it.
    assert 0.5 < result.fitness < 0.9
    # no rigid pose fits a bent map: the best one stays within the bend's own range (7.2 degrees
    # from end to end; the far end moves about 1 m), here 0.79 m and 7.3 degrees
    dxy, dyaw = pose_error(t_true, result.transform)
    assert dxy < 1.5 and dyaw < 8.0


def test_other_building_scores_low(truth, aligned):
    other = synth.wall_points(synth.building_plan(7, 18.0, 20.0), spacing=0.05, noise=0.015,
                              seed=3)
    _, map_xy = to_map_frame(other, 15, 5.0, -3.0)  # a pose of test_rigid_full_map
    wrong = align(map_xy, truth)
    assert wrong.fitness < 0.6 < 0.9 < aligned(15, 5.0, -3.0)[1].fitness
    assert isinstance(wrong, Alignment) and wrong.method == "coarse+icp"


def test_init_skips_global_search(truth, scan):
    t_true, map_xy = to_map_frame(scan, 172, 35.0, 40.0)
    # Off by 3 degrees about the plan's centre, then by (0.5, -0.4) m, in the truth frame.
    turn = np.radians(3.0)
    centre = np.array([WIDTH / 2, HEIGHT / 2])
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    shift = centre - rot @ centre + [0.5, -0.4]
    init = Similarity2D(shift[0], shift[1], turn).compose(t_true)
    result = align(map_xy, truth, init=init)
    dxy, dyaw = pose_error(t_true, result.transform)
    assert result.method == "init+icp" and dxy < 0.05 and dyaw < 0.2 and result.fitness > 0.9


def test_refine_best_scores_only_to_choose():
    """One start is refined without a score (nothing to choose); several are ranked by
    fitness, then RMSE, and the best finalist wins."""
    calls = []

    def scored(tf: Similarity2D) -> Alignment:
        calls.append(tf)
        return Alignment(tf, fitness=1.0 - abs(tf.tx - 2.0) / 10, rmse_m=0.0,
                         tolerance_m=0.2, method="")

    def rough(tf: Similarity2D) -> Similarity2D:
        return Similarity2D(tf.tx + 1.0, tf.ty, tf.yaw)

    def fine(tf: Similarity2D) -> Similarity2D:
        return Similarity2D(tf.tx, tf.ty + 1.0, tf.yaw)

    assert refine_best([Similarity2D(5.0, 0.0, 0.0)], rough, fine, scored, 2) == \
        Similarity2D(6.0, 1.0, 0.0)
    assert calls == []
    starts = [Similarity2D(x, 0.0, 0.0) for x in (7.0, 1.0, -3.0)]
    assert refine_best(starts, rough, fine, scored, 2) == Similarity2D(2.0, 1.0, 0.0)
    assert len(calls) == 3 + 2


def test_no_refine_scores_identity(truth, scan):
    result = align(scan, truth, refine=False)
    assert result.method == "none" and result.transform == Similarity2D()
    assert result.fitness > 0.99
    turned = align(to_map_frame(scan, 90, 0.0, 0.0)[1], truth, refine=False)
    assert turned.fitness < 0.3


def test_params_reach_the_alignment(scan, truth):
    """A tighter tolerance counts fewer inliers (1.5 cm noise: about 2/3 within 2 cm)."""
    loose = align(scan, truth, refine=False)
    tight = align(scan, truth, AlignParams(tolerance=0.02), refine=False)
    assert tight.tolerance_m == 0.02 and 0.5 < tight.fitness < loose.fitness
    assert AlignParams().finalists_for(scale=False) == 2
    assert AlignParams().finalists_for(scale=True) == 3
    assert AlignParams(finalists=1).finalists_for(scale=True) == 1


def test_deterministic(truth, scan, aligned):
    box = (-1.0, -1.0, 0.5 * WIDTH, 17.0)  # a case of test_partial_map
    _, map_xy = to_map_frame(inside(scan, box), 33, 8.0, -6.0)
    assert align(map_xy, truth) == aligned(33, 8.0, -6.0, box)[1]


def test_coarse_candidates_rank_right_pose_first(truth, scan):
    t_true, map_xy = to_map_frame(scan, 90, -20.0, 12.0)
    best = coarse_search(voxel_centroids(map_xy, 0.05),
                         voxel_centroids(truth, 0.05)).candidates[0]
    dxy, dyaw = pose_error(t_true, best.transform)
    assert dxy < 0.6 and dyaw < 2.0 and 0.0 < best.score <= 1.0


def test_score_counts_inliers_and_rmse():
    truth = np.array([[0.0, 0.0], [1.0, 0.0]])
    map_xy = np.array([[0.1, 0.0], [1.0, 0.0], [5.0, 5.0], [-0.15, 0.0]])
    fitness, rmse = score(map_xy, truth, Similarity2D(), tolerance=0.2)
    assert fitness == pytest.approx(0.75)
    assert rmse == pytest.approx(np.sqrt((0.1**2 + 0.0 + 0.15**2) / 3))
    assert score(map_xy, truth, Similarity2D(tx=100.0)) == (0.0, 0.0)


def test_voxel_centroids_in_the_plane():
    """2D points: one centroid per cell, cells sorted by x index, then y index."""
    xy = np.array([[0.51, 0.0], [0.01, 0.31], [0.52, 0.02], [0.03, -0.17], [0.01, -0.13]])
    out = voxel_centroids(xy, 0.1)
    np.testing.assert_allclose(out, [[0.02, -0.15], [0.01, 0.31], [0.515, 0.01]])


def test_empty_map_scores_zero(truth):
    result = align(np.empty((0, 2)), truth)
    assert result.fitness == 0.0 and result.transform == Similarity2D()


def test_gridded_map_equal_to_truth_aligns_exactly():
    """Two identical gridded clouds: point-to-point ICP alone locked onto the lattice 6 cm off;
    the point-to-line stage must bring it back to the identity."""
    plan = synth.building_plan(0)
    grid = synth.plan_grid(plan, 0.05)
    xy = grid.cell_centres(synth.render(plan, grid) == synth.OCCUPIED)
    tf = align(xy, xy).transform
    assert np.hypot(tf.tx, tf.ty) < 1e-3 and abs(tf.yaw_deg) < 0.01


def test_pyramid_bound_holds(campus):
    """A region's bound is at least the score of every child in it, and descend's best pose
    is where the map lies."""
    from pcmapq.align.pyramid import _Level, descend

    t_true, map_xy, truth_xy = campus
    # 20 000 of the map's points, evenly spread, hit every cell of the sweep's 6 m rasters and
    # more voxels than the descent keeps (max_points) at each of its levels
    map_xy = evenly(map_xy, 20_000)
    search = coarse_search(map_xy, truth_xy, resolution=6.0)
    level = _Level(map_xy - search.centre, truth_xy, 3.0, search.radius + 12.0, 5000)
    for _, yaw, x, y in search.poses[:40, :4]:
        bound = level.mean(level.bound, level.pixels(np.array([yaw]), np.array([x, y])))[0]
        assert level.children(yaw, np.array([x, y]), 0.5 * search.yaw_step)[0] <= bound
    found = descend(search, map_xy, truth_xy, finest=0.5, beam=16, top_k=4)
    assert found.cell == 0.375  # 6 m halved until at most 0.5 m
    dxy, dyaw = pose_error(t_true, found.candidates[0].transform)
    assert dxy < 0.75 and dyaw < 0.5, (dxy, dyaw)


def test_pyramid_children_read_zero_off_the_field(campus):
    """A child's score is the mean of the (padded) field under its shifted points, 0 where a
    point falls off it: checked shift by shift for poses on, across and off the field."""
    from pcmapq.align.pyramid import SHIFT, _Level

    _, map_xy, truth_xy = campus
    level = _Level(map_xy - map_xy.mean(axis=0), truth_xy, 3.0, 3.0, 2000)  # walls at its edge
    rows, cols = level.field.shape
    rng = np.random.default_rng(0)
    lo, hi = truth_xy.min(axis=0) - 150.0, truth_xy.max(axis=0) + 150.0
    for yaw, x, y in zip(rng.uniform(0, 2 * np.pi, 20), *rng.uniform(lo, hi, (20, 2)).T,
                         strict=True):
        best = -1.0
        for turn in (-1, 0, 1):
            uv = level.pixels(np.array([yaw + 0.02 * turn]), np.array([x, y]))[0]
            for dv in range(-SHIFT, SHIFT + 1):
                for du in range(-SHIFT, SHIFT + 1):
                    u, v = uv[:, 0] + du, uv[:, 1] + dv
                    on = (u >= 0) & (u < cols) & (v >= 0) & (v < rows)
                    read = level.field[np.clip(v, 0, rows - 1), np.clip(u, 0, cols - 1)]
                    best = max(best, float(np.where(on, read, 0.0).mean()))
        child = level.children(yaw, np.array([x, y]), 0.02)
        assert child[0] == pytest.approx(best, rel=1e-6, abs=1e-9)


def test_line_normals_on_demand_equal_the_whole_batch(truth):
    """LineTarget computes a truth point's normal the first time a map point pairs with it; a
    normal depends on its point alone, so any order and batch gives the normals computed for
    every point at once, bit for bit; on the plan's axis-aligned walls they are axis-aligned."""
    from scipy.spatial import cKDTree

    from pcmapq.align.point_to_line import LineTarget, line_normals

    xy = voxel_centroids(truth, 0.05)
    tree = cKDTree(xy)
    whole = line_normals(tree, np.arange(len(xy)))
    target = LineTarget(xy, tree)
    rng = np.random.default_rng(0)
    for size in (1, 7, 500, len(xy)):
        index = rng.integers(0, len(xy), size)
        np.testing.assert_array_equal(target.normals(index), whole[index])
    assert np.median(np.abs(whole).max(axis=1)) > 0.999


def test_thinned_map_runs_light_icp_and_lands():
    """A map of more voxels than ``max_points`` is thinned; its point-to-point stages then run on
    ICP_POINTS of its points against the truth at THINNED_TRUTH_VOXEL, and the point-to-line
    finish on all of them. A campus of 3 x 2 copies of the plan, thinned from 0.05 m voxels to
    about 0.13 m, lands within 0.05 m and 0.05 degrees."""
    from pcmapq.align.planar import ICP_POINTS, THINNED_TRUTH_VOXEL, _icp_inputs
    from pcmapq.core.voxels import thinned

    t_true, map_xy, truth_xy = synth.placed_campus(3, 2)
    params = AlignParams(max_points=8_000)
    map_ds, map_voxel = thinned(map_xy, params.voxel, params.max_points)
    assert map_voxel > params.voxel and len(map_ds) > ICP_POINTS
    icp_map, schedule = _icp_inputs(map_ds, True, ((1.0, 0.2), (0.2, 0.05)))
    assert len(icp_map) == ICP_POINTS and np.ptp(icp_map, axis=0) == pytest.approx(
        np.ptp(map_ds, axis=0), rel=0.02)  # spread over the whole map
    assert schedule == ((1.0, THINNED_TRUTH_VOXEL), (0.2, THINNED_TRUTH_VOXEL))
    result = align(map_xy, truth_xy, params)
    dxy, dyaw = pose_error(t_true, result.transform)
    assert dxy < 0.05 and dyaw < 0.05, (dxy, dyaw)
    assert result.fitness > 0.99


def test_refine_best_breaks_a_fitness_tie_by_the_truth_covered():
    """Given ``covered``, a finalist within TIE_FITNESS of the best fitness that covers
    TIE_COVERAGE more of the truth wins; a smaller gain in coverage, or a clear lead in
    fitness, keeps the fittest."""
    def run(fitness: dict[float, float], cover: dict[float, float]) -> float:
        def scored(tf: Similarity2D) -> Alignment:
            return Alignment(tf, fitness=fitness[tf.tx], rmse_m=0.0, tolerance_m=0.2, method="")

        starts = [Similarity2D(x, 0.0, 0.0) for x in fitness]
        return refine_best(starts, lambda tf: tf, lambda tf: tf, scored, len(starts),
                           covered=lambda tf: cover[tf.tx]).tx

    tie = TIE_FITNESS / 2
    assert run({0.0: 0.43, 10.0: 0.43 - tie}, {0.0: 0.2, 10.0: 0.6}) == 10.0
    assert run({0.0: 0.43, 10.0: 0.43 - tie}, {0.0: 0.2, 10.0: 0.2 + TIE_COVERAGE / 2}) == 0.0
    assert run({0.0: 0.43, 10.0: 0.43 - 2 * TIE_FITNESS}, {0.0: 0.2, 10.0: 0.9}) == 0.0
