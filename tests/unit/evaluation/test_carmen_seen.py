"""A CARMEN log given as the map carries the area its scans saw (its free space), as
``pcmapq track`` gives its steps: known answer, a square room scanned from its inside."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.evaluation.inputs import MAP_CROP, TRUTH_CROP, load_input
from pcmapq.io.carmen import beam_angles
from pcmapq.io.clouds import SEEN_CELL
from pcmapq.settings import SourceConfig
from testkit.carmen import flaser_log

#: The room: walls at x, y = +-HALF metres.
HALF = 4.0


def ranges_in_room(pose: np.ndarray, beams: int) -> np.ndarray:
    """The ranges (metres) from ``pose`` (x, y, theta) to the room's walls, ray by ray."""
    heading = pose[2] + beam_angles(beams)
    c, s = np.cos(heading), np.sin(heading)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (HALF - pose[0]) / c, (-HALF - pose[0]) / c)
        ty = np.where(s > 0, (HALF - pose[1]) / s, (-HALF - pose[1]) / s)
    return np.minimum(np.abs(tx), np.abs(ty))


@pytest.fixture
def room_log(tmp_path):
    """Four scans of 361 beams (half a turn each) from the room's middle, facing the four
    ways: together they see the whole room."""
    poses = np.array([[0.0, 0.0, a] for a in (0.0, np.pi / 2, np.pi, -np.pi / 2)])
    ranges = np.stack([ranges_in_room(p, 361) for p in poses])
    return flaser_log(tmp_path / "room.log", ranges, poses)


def test_the_map_side_sees_the_room_and_nothing_beyond_its_walls(room_log):
    source = load_input(room_log, SourceConfig(), MAP_CROP)
    seen = source.seen
    assert seen is not None
    rows, cols = np.nonzero(seen.cells)
    x = (cols + seen.corner[0] + 0.5) * SEEN_CELL
    y = (rows + seen.corner[1] + 0.5) * SEEN_CELL
    area = len(x) * SEEN_CELL ** 2
    assert area == pytest.approx((2 * HALF) ** 2, rel=0.05)
    assert np.abs(x).max() <= HALF + SEEN_CELL and np.abs(y).max() <= HALF + SEEN_CELL


def test_the_truth_side_and_a_cropped_map_carry_no_views(room_log):
    assert load_input(room_log, SourceConfig(), TRUTH_CROP).seen is None
    cropped = SourceConfig(crop=(-5.0, -5.0, 0.0, 5.0))
    assert load_input(room_log, cropped, MAP_CROP).seen is None
