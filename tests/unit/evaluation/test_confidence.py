"""The confidence that one pose places the map (pcmapq.evaluation.same_place): the smaller of its
terms, and the distinctiveness of known search scores."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align.coarse import Search, distinctiveness
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.same_place import confidence


def test_confidence_is_the_smaller_term():
    """min(distinct / 0.2, (recall - 0.4) / 0.4), clipped; no search: the recall term (and the
    share, full by default)."""
    assert confidence(0.1, 0.6) == pytest.approx(0.5)
    assert confidence(0.05, 0.8) == pytest.approx(0.25)
    assert confidence(0.3, 0.7) == pytest.approx(0.75)
    assert confidence(None, 0.7) == pytest.approx(0.75)
    assert confidence(0.5, 1.0) == 1.0 and confidence(0.0, 1.0) == 0.0
    assert confidence(None, 0.2) == 0.0


def test_a_map_with_a_sliver_on_the_truth_has_no_confidence():
    """The larger of coverage and fitness: (share - 0.2) / 0.2, the smallest term; a partial
    map (low coverage, high fitness) or one larger than its truth (the reverse) keeps the
    other terms' confidence."""
    assert confidence(None, 0.82, share=0.19) == 0.0  # the sample 14 m off its plan
    assert confidence(None, 1.0, share=0.3) == pytest.approx(0.5)
    assert confidence(0.5, 0.8, share=0.25) == pytest.approx(0.25)
    assert confidence(None, 0.7, share=0.9) == confidence(None, 0.7) == pytest.approx(0.75)


def test_distinctiveness_of_known_scores():
    """Best score near the pose 0.8, best elsewhere 0.6 (turned by 90 degrees, or moved by a
    whole map radius): 1 - 0.6 / 0.8 = 0.25; a far pose scoring above the near one gives 0."""
    poses = np.array([[0.8, 0.0, 5.0, 5.0],    # at the pose
                      [0.7, 0.1, 5.2, 5.0],    # near it: 6 degrees, 0.2 m
                      [0.6, np.pi / 2, 5.0, 5.0],
                      [0.5, 0.0, 15.0, 5.0]])
    search = Search([], poses, np.zeros(2), 10.0)
    tf = Similarity2D(5.0, 5.0, 0.0)
    assert distinctiveness(search, tf) == pytest.approx(0.25)
    assert distinctiveness(search, Similarity2D(15.0, 5.0, 0.0)) == 0.0
    scaled = Search([], np.column_stack([poses, np.log([1.0, 1.0, 1.0, 1.0])]), np.zeros(2), 10)
    assert distinctiveness(scaled, tf) == pytest.approx(0.25)
    assert distinctiveness(scaled, Similarity2D(5.0, 5.0, 0.0, 1.5)) == 0.0  # other scale


def test_low_confidence_needs_free_space_that_agrees():
    """Below the minimum confidence, a map with free space is scored with low confidence
    unless it saw through 0.1 or more of the truth's walls it covers, less than 0.8 of its
    free cells lie on the truth, or 0.4 or less of the truth's walls lie near its walls; a
    binary map (no free space) is refused as before."""
    from pcmapq.evaluation.same_place import verdict
    from pcmapq.results.result import LOW, OTHER

    assert verdict(0.0, 0.5, (), 0.0, 0.86, 0.048, 0.998) == LOW  # the one-room house map
    assert verdict(0.0, 0.5, (), 0.0, 0.63, 0.327, 0.93) == OTHER  # it saw through the walls
    assert verdict(0.0, 0.5, (), 0.0, 0.40, 0.0, 1.0) == OTHER  # the truth's walls not near it
    assert verdict(0.0, 0.5, (), 0.0, 0.86, 0.048) == OTHER  # not weighed by a rigid search
    assert verdict(0.0, 0.5, (), 0.0, 0.90, 0.061, 0.52) == OTHER  # its free space off it
    assert verdict(0.0, 0.5, (), 0.0, 0.86) == OTHER  # no free space
