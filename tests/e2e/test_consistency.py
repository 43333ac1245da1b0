"""Bad maps of the right place: scored, with the verdict that no single pose fits them and
where they break. Known answers: maps bent or broken apart by a known amount; a map of another
place still refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.errors import EvaluationError
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import PointMap
from pcmapq.results.result import INCONSISTENT, Result
from pcmapq.settings import MatchingConfig, Settings
from testkit import synth
from testkit.files import write_image_map
from testkit.paths import SAMPLE

TRUE = Similarity2D(3.0, -2.0, np.radians(37.0))
FAST = Settings(matching=MatchingConfig(detectors=()))


def _broken(plan: np.ndarray, degrees: float) -> np.ndarray:
    """Wall points of ``plan`` whose eastern half (x > 12 m) is turned by ``degrees`` about
    (12, 8) m, in the map frame of TRUE."""
    points = synth.wall_points(plan)
    east = points[:, 0] > 12
    pivot = np.array([12.0, 8.0])
    points[east] = Similarity2D(0, 0, np.radians(degrees)).apply(points[east] - pivot) + pivot
    return TRUE.inverse().apply(points)


def _cloud(xy: np.ndarray, name: str = "map.npy") -> PointMap:
    return PointMap(Path(name), np.column_stack([xy, np.zeros(len(xy))]), False)


@pytest.mark.parametrize("seed", [0, 2])
def test_a_map_broken_in_two_is_scored_and_says_where(seed, tmp_path):
    """The eastern half of the map turned by 20 degrees: no pose fits it whole (confidence
    0.24 and 0.29; it was refused as another place), its western parts placed on their own
    agree with its pose, so it is scored, and it breaks most in the eastern half: the regions
    there, fitted from the eastern parts' own poses, move by what undoes the turn (up to 5 m,
    beyond ICP's reach from the map's pose)."""
    plan = synth.building_plan(seed)
    truth = write_image_map(plan, tmp_path / "truth.png")
    result = evaluate(_cloud(_broken(plan, 20.0)), truth, FAST)
    cover = result.overlap
    assert cover.confidence < 0.5 and cover.verdict == INCONSISTENT
    assert sum(p.agrees for p in cover.parts) >= 3
    agreeing = np.array([p.centre_m for p in cover.parts if p.agrees])
    assert (agreeing[:, 0] < 12).all()  # the parts that agree are western
    c = result.consistency
    k = c.largest()
    assert c.centre[k][0] > 12 and 4.0 < c.offset_m[k] < 5.2
    assert np.median(c.offset_m[c.centre[:, 0] < 10]) < 0.1  # the west needs no move


def test_another_place_is_still_refused(tmp_path):
    """Three round rooms against the building: no part lands near the pose; refused, and the
    message counts the parts."""
    truth = write_image_map(synth.building_plan(0), tmp_path / "truth.png")
    with pytest.raises(EvaluationError, match=r"[012] of its 8 parts"):
        evaluate(_cloud(synth.wall_points(synth.round_rooms())), truth, FAST)


def test_consistency_in_json_csv_and_back(tmp_path):
    """The regions and parts survive JSON; the regions CSV holds the JSON's rows."""
    plan = synth.building_plan(0)
    truth = write_image_map(plan, tmp_path / "truth.png")
    result = evaluate(_cloud(_broken(plan, 20.0)), truth, FAST)
    doc = json.loads(result.to_json())
    assert doc["alignment"]["verdict"] == INCONSISTENT and len(doc["alignment"]["parts"]) == 8
    regions_doc = doc["consistency"]["regions"]
    assert len(regions_doc) == len(result.consistency.points) > 0
    assert Result.from_json(result.to_json()).to_json() == result.to_json()
    lines = result.regions_csv().splitlines()
    assert lines[0].startswith("x_m,y_m,dx_m,dy_m,offset_m,turn_deg")
    assert len(lines) == len(regions_doc) + 1
    first = lines[1].split(",")
    assert float(first[4]) == pytest.approx(regions_doc[0]["offset_m"], abs=1e-6)


def test_the_samples_moved_wall_is_where_its_regions_move():
    """The shipped sample's room wall stands 0.3 m east of the plan's (x = 8.3 m instead of
    8.0 m, from y = 0 to 6.8 m): the regions holding it fit the truth moved 0.3 m west (within
    5 cm); the other held regions hardly move (median under 5 cm)."""
    sample = SAMPLE
    c = evaluate(sample / "scan.ply", sample / "truth.png", FAST).consistency
    wall = (c.centre[:, 0] >= 8.0) & (c.centre[:, 0] < 12.0) & (c.centre[:, 1] < 7.0)
    assert wall.sum() >= 2 and c.held[wall].all()
    np.testing.assert_allclose(c.offset[wall], [[-0.3, 0.0]] * int(wall.sum()), atol=0.05)
    assert np.median(c.offset_m[c.held & ~wall]) < 0.05
