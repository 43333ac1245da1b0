"""Drawing maps into the truth's grid."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.raster import draw
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN, hit_counts, points_to_grid, warp_state
from pcmapq.raster.footprint import footprint_rule
from testkit import synth


def state_of(img: np.ndarray) -> np.ndarray:
    out = np.full(img.shape, UNKNOWN, np.int8)
    out[img == synth.FREE] = FREE
    out[img == synth.OCCUPIED] = OCCUPIED
    return out


def iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / (a | b).sum())


def test_hit_counts_and_min_hits():
    grid = MetricGrid(0.1, (0.0, 0.0, 0.0), (10, 10))
    xy = np.array([[0.05, 0.05], [0.06, 0.04], [0.55, 0.95], [5.0, 5.0]])  # last one outside
    counts = hit_counts(xy, grid)
    assert counts.sum() == 3 and counts[9, 0] == 2 and counts[0, 5] == 1
    assert points_to_grid(xy, grid, min_hits=2).sum() == 1


def test_hit_counts_in_chunks_of_moved_points_are_the_counts_of_the_whole(monkeypatch):
    """Points moved and counted a chunk at a time (walls here and there, some off the grid)
    give the counts of all of them moved at once."""
    rng = np.random.default_rng(3)
    grid = MetricGrid(0.05, (-2.0, -1.0, 0.0), (300, 400))
    xy = np.vstack([rng.uniform(-5, 25, (3000, 2)), rng.normal(4, 0.3, (3000, 2)),
                    rng.normal(12, 0.2, (3000, 2))])
    move = Similarity2D(1.5, -0.5, np.radians(20.0), 1.2).apply
    whole = hit_counts(move(xy), grid)
    monkeypatch.setattr(draw, "CHUNK", 1000)
    assert np.array_equal(hit_counts(xy, grid, move), whole)
    assert 0 < whole.sum() < len(xy)  # points on and off the grid
    assert np.array_equal(points_to_grid(xy, grid, 2, move=move), whole >= 2)


def test_warp_identity_is_exact(plan):
    grid = synth.plan_grid(plan, 0.05)
    state = state_of(synth.render(plan, grid))
    np.testing.assert_array_equal(warp_state(state, grid, Similarity2D(), grid), state)


def test_warp_with_rotation_and_scale(plan):
    """A map drawn in half-size units (p_truth = 2 R p_map + t), at a fine resolution, lands on
    the truth's walls."""
    truth_grid = synth.plan_grid(plan, 0.05)
    truth = synth.render(plan, truth_grid) == synth.OCCUPIED
    tf = Similarity2D(3.0, -1.0, np.radians(35.0), 2.0)
    segments = synth.transform_segments(plan, tf.inverse())
    map_grid = synth.plan_grid(segments, 0.0125)  # 0.025 m cells once scaled
    img = synth.render(segments, map_grid, thickness=0.075)
    warped = warp_state(state_of(img), map_grid, tf, truth_grid)
    # the same map in metres (scale 1, 0.025 m cells) warps to the same cells
    rigid = Similarity2D(tf.tx, tf.ty, tf.yaw)
    metric = synth.transform_segments(plan, rigid.inverse())
    metric_grid = synth.plan_grid(metric, 0.025)
    same = warp_state(state_of(synth.render(metric, metric_grid)), metric_grid, rigid, truth_grid)
    assert iou(warped == OCCUPIED, same == OCCUPIED) > 0.95
    # turned walls come out a little thicker (a cell is occupied from a third of it)
    assert iou(warped == OCCUPIED, truth) > 0.7
    assert (warped == UNKNOWN).sum() < 0.35 * warped.size  # the plan's box is known


def _rule(state: np.ndarray, requested: str = "auto") -> str:
    return footprint_rule(requested, state == UNKNOWN, 0.05)


def test_footprint_rule_tells_binary_images_from_occupancy_maps():
    """auto: known cells when the image has unknown regions (>= 1 % of it in patches at least
    0.5 m wide), the walls' enclosed area when it has none."""
    binary = np.full((200, 200), FREE, np.int8)  # 10 m x 10 m, 0.05 m cells
    binary[50, 20:180] = OCCUPIED
    assert _rule(binary) == "walls"
    framed = binary.copy()  # a grey frame 4 cells (0.2 m) wide: not a region
    framed[:4], framed[-4:], framed[:, :4], framed[:, -4:] = UNKNOWN, UNKNOWN, UNKNOWN, UNKNOWN
    assert (framed == UNKNOWN).mean() > 0.07 and _rule(framed) == "walls"
    blurred = binary.copy()  # anti-aliased wall edges and stray grey pixels
    blurred[[49, 51], 20:180] = UNKNOWN
    blurred[::7, ::11] = UNKNOWN
    assert _rule(blurred) == "walls"
    strip = binary.copy()  # an unknown strip 0.4 m wide across the map: narrower than 0.5 m
    strip[100:108] = UNKNOWN
    assert _rule(strip) == "walls"
    explored = binary.copy()  # an unexplored 1 m x 2.5 m room: 2.5 % of the image
    explored[120:140, 20:70] = UNKNOWN
    assert _rule(explored) == "known"
    tiny = binary.copy()  # a 0.6 m x 0.6 m grey patch (a legend?): 0.4 %, below 1 %
    tiny[150:162, 150:162] = UNKNOWN
    assert _rule(tiny) == "walls"
    for rule in ("known", "walls", "all"):  # explicit choices are kept
        assert _rule(binary, rule) == rule and _rule(explored, rule) == rule


def test_footprint_rule_of_a_cloud():
    assert footprint_rule("auto", None, 0.0) == "walls"
    assert footprint_rule("all", None, 0.0) == "all"
    with pytest.raises(ValueError, match="no known cells"):
        footprint_rule("known", None, 0.0)
    with pytest.raises(ValueError, match="unknown footprint rule"):
        footprint_rule("everything", None, 0.0)
