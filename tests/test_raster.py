"""Drawing maps into the truth's grid."""

from __future__ import annotations

import numpy as np

from pcmapq import synth
from pcmapq.align.transform import Similarity2D
from pcmapq.grid import MetricGrid
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN, hit_counts, points_to_grid, warp_state


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
