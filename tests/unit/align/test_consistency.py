"""Where a map breaks, piece by piece: the verdict of a known confidence and parts, the map cut
along its principal axes, and region offsets that follow a known bend."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align import align
from pcmapq.align.parts import Part, pieces
from pcmapq.align.point_to_line import LineTarget
from pcmapq.align.regions import regions
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import voxel_centroids
from pcmapq.evaluation.same_place import verdict
from pcmapq.results.result import INCONSISTENT, OTHER, SAME
from testkit import synth

TRUE = Similarity2D(3.0, -2.0, np.radians(37.0))


def _part(agrees: bool) -> Part:
    return Part(0.125, (0.0, 0.0), 0.0 if agrees else 9.0, 0.0, 0.5, agrees)


def test_verdict_of_known_confidence_and_parts():
    """The confidence settles it when it reaches the minimum; below it, three agreeing parts
    make a map of the truth's place that no pose fits whole, two do not."""
    assert verdict(0.5, 0.5, ()) == SAME
    assert verdict(0.49, 0.5, [_part(True)] * 3 + [_part(False)] * 5) == INCONSISTENT
    assert verdict(0.49, 0.5, [_part(True)] * 2 + [_part(False)] * 6) == OTHER
    assert verdict(0.0, 0.5, ()) == OTHER


def test_a_pose_that_stands_out_shows_the_place_with_few_parts_agreeing():
    """Below the minimum confidence, a pose whose distinctiveness reaches 0.3 with more than
    0.4 of the truth near the map is the truth's place whatever its parts say; a less distinct
    pose (another place's reach 0.235), or as distinct with 0.4 of the truth, is not."""
    few = [_part(True)] + [_part(False)] * 7
    assert verdict(0.28, 0.5, few, 0.42, 0.51) == INCONSISTENT
    assert verdict(0.28, 0.5, (), 0.30, 0.41) == INCONSISTENT
    assert verdict(0.05, 0.5, few, 0.24, 0.42) == OTHER
    assert verdict(0.0, 0.5, few, 0.9, 0.40) == OTHER
    assert verdict(0.28, 0.5, few, None, 0.51) == OTHER


def test_pieces_cut_along_the_principal_axes():
    """A long, turned cloud is cut into 4 x 2 pieces of equal count, the first index along
    its length."""
    rng = np.random.default_rng(0)
    along = rng.uniform(-20, 20, 4000)
    xy = np.column_stack([along, rng.uniform(-2, 2, 4000)]) @ np.array([[0.6, 0.8],
                                                                         [-0.8, 0.6]])
    index = pieces(xy, 4, 2)
    assert np.bincount(index).tolist() == [500] * 8
    for k in range(4):  # pieces 2k and 2k + 1 share a quarter of the length
        assert np.ptp(along[index // 2 == k]) < 10.5


@pytest.mark.parametrize("degrees_per_metre", [0.1, 0.2])
def test_region_offsets_follow_a_bend(degrees_per_metre):
    """A map bent like odometry drift (the far end 0.4 and 0.9 m off): each region's offset
    correlates with the displacement that undoes the bend there (r >= 0.9 over x and y)."""
    plan = synth.building_plan(0)
    truth = voxel_centroids(synth.wall_points(plan), 0.05)
    where = synth.wall_points(plan, seed=1)
    drawn = TRUE.inverse().apply(synth.bend(where, degrees_per_metre))
    pose = align(drawn, truth).transform
    c = regions(drawn, pose, LineTarget(truth))
    placed = pose.apply(drawn)
    cell = np.floor(placed / c.tile_m).astype(int)
    expected = np.array([(where - placed)[(cell == np.floor(centre / c.tile_m)).all(axis=1)]
                         .mean(axis=0) for centre in c.centre])
    held = c.held
    assert held.sum() >= 20
    r = np.corrcoef(expected[held].ravel(), c.offset[held].ravel())[0, 1]
    assert r >= 0.9, r
