"""Detectors: stable under re-rasterisation, resolution independent, and LiDAR faces vs plans."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq import synth
from pcmapq.align.transform import Similarity2D
from pcmapq.features import DETECTORS, Features, detect
from pcmapq.grid import MetricGrid
from pcmapq.match import match
from pcmapq.raster import draw

NAMES = ("harris", "hough", "sift")


@pytest.fixture(scope="module")
def plan() -> np.ndarray:
    return synth.building_plan(0)


@pytest.fixture(scope="module")
def grid(plan) -> MetricGrid:
    return synth.plan_grid(plan, 0.05)


@pytest.fixture(scope="module")
def truth(plan, grid) -> dict[str, Features]:
    occ = synth.render(plan, grid) == synth.OCCUPIED
    return {name: detect(name, occ, grid) for name in NAMES}


def scores(truth: dict[str, Features], occ: np.ndarray, grid: MetricGrid) -> dict:
    """(quality, precision) per detector of the map ``occ`` against the truth features."""
    out = {}
    for name in NAMES:
        m = match(name, truth[name], detect(name, occ, grid))
        out[name] = (m.quality, m.precision)
    return out


def test_registry_and_types(truth):
    assert set(NAMES) <= set(DETECTORS)
    for name, f in truth.items():
        assert f.xy.shape == (len(f), 2) and f.strength.shape == (len(f),)
        assert f.strong.dtype == bool and f.strong.sum() >= 10, name
    assert truth["sift"].descriptors.shape == (len(truth["sift"]), 128)
    assert truth["sift"].descriptors.dtype == np.float32
    assert truth["hough"].segments.shape == (len(truth["hough"]), 4)


def test_deterministic(plan, grid, truth):
    occ = synth.render(plan, grid) == synth.OCCUPIED
    for name in NAMES:
        again = detect(name, occ, grid)
        np.testing.assert_array_equal(again.xy, truth[name].xy)
        np.testing.assert_array_equal(again.strong, truth[name].strong)


def test_map_equals_truth(truth):
    for name in NAMES:
        m = match(name, truth[name], truth[name])
        assert m.quality >= 0.98 and m.precision >= 0.98, name


def test_half_cell_shift(plan, grid, truth):
    ox, oy, _ = grid.origin
    shifted = MetricGrid(0.05, (ox + 0.025, oy + 0.025, 0.0), grid.shape)
    occ = synth.render(plan, shifted) == synth.OCCUPIED
    for name, (q, p) in scores(truth, occ, shifted).items():
        assert q >= 0.95 and p >= 0.95, (name, q, p)


def test_turned_and_warped_back(plan, grid, truth):
    tf = Similarity2D(yaw=np.radians(23.0))
    turned = synth.transform_segments(plan, tf)
    tgrid = synth.plan_grid(turned, 0.05)
    state = np.where(synth.render(turned, tgrid) == synth.OCCUPIED, draw.OCCUPIED, draw.FREE)
    occ = draw.warp_state(state, tgrid, tf.inverse(), grid) == draw.OCCUPIED
    for name, (q, _) in scores(truth, occ, grid).items():
        assert q >= 0.95, (name, q)


def test_resolution_independent(plan, grid, truth):
    fine = synth.plan_grid(plan, 0.025)
    occ = synth.render(plan, fine) == synth.OCCUPIED
    for name, (q, _) in scores(truth, occ, fine).items():
        # q at 0.05 m against itself is 1. synth.render draws walls 0.2 m thick at 0.05 m and
        # 0.15 m at 0.025 m, which moves a few SIFT keypoints (entropy depends on thickness).
        assert q >= (0.9 if name == "sift" else 0.95), (name, q)


def test_lidar_faces_vs_filled_plan(plan, grid, truth):
    occ = draw.points_to_grid(synth.wall_points(plan, spacing=0.02, noise=0.01), grid)
    for name, (q, _) in scores(truth, occ, grid).items():
        assert q >= 0.9, (name, q)


def test_moved_wall_shows_its_displacement(plan, grid, truth):
    x0, y0, _, y1 = plan[5]  # a vertical room wall
    moved = synth.move_wall(plan, 5, (0.5, 0.0))
    occ = synth.render(moved, grid) == synth.OCCUPIED
    for name in ("harris", "hough"):
        m = match(name, truth[name], detect(name, occ, grid), threshold=1.0)
        xy = truth[name].xy[m.truth_idx]
        near = (np.abs(xy[:, 0] - x0) < 0.4) & (xy[:, 1] > y0 - 0.5) & (xy[:, 1] < y1 + 0.5)
        dist = np.linalg.norm(m.displacement, axis=1)
        assert near.any(), name
        np.testing.assert_allclose(dist[near], 0.5, atol=0.1, err_msg=name)
        assert np.all(dist[~near] < 0.1), name
    hough = match("hough", truth["hough"], detect("hough", occ, grid), threshold=1.0)
    seg = truth["hough"].segments[hough.truth_idx]
    vertical = np.abs(seg[:, 2] - seg[:, 0]) < np.abs(seg[:, 3] - seg[:, 1])
    on_wall = np.abs(truth["hough"].xy[hough.truth_idx, 0] - x0) < 0.2
    moved_wall = np.flatnonzero(vertical & on_wall)
    np.testing.assert_allclose(hough.displacement[moved_wall], [[0.5, 0.0]], atol=0.1)


def test_empty_map(grid):
    empty = np.zeros(grid.shape, dtype=bool)
    for name in NAMES:
        f = detect(name, empty, grid)
        assert len(f) == 0 and f.xy.shape == (0, 2), name
