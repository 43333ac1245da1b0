"""The arrows' scale and convention (report/arrows.py): a round scale within its bounds, a
region's arrow from where it fits the truth to where the map has it."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from pcmapq.report.arrows import arrow_label, arrow_scale, region_arrows, round_scale
from pcmapq.report.style import MAX_ARROW_SCALE


@pytest.mark.parametrize(("bound", "scale"), [
    (0.3, 1.0), (1.0, 1.0), (1.99, 1.0), (2.9, 2.0), (5.0, 5.0), (7.85, 5.0), (10.0, 10.0),
    (19.99, 10.0), (50.3, 50.0), (99.0, 50.0), (1e9, MAX_ARROW_SCALE), (np.inf, 100.0)])
def test_round_scale_is_the_largest_round_number_within_its_bounds(bound, scale):
    assert round_scale(bound) == scale


def test_a_regions_arrow_goes_from_the_truth_to_the_map():
    """A region whose map points stand 0.3 m east of the truth (its offset, the move that fits
    it to the truth, is 0.3 m west): its arrow starts 0.3 m west of its centre and points
    0.3 m east, as a feature's displacement does."""
    consistency = SimpleNamespace(centre=np.array([[10.0, 2.0], [4.0, 4.0]]),
                                  offset=np.array([[-0.3, 0.0], [0.0, 0.1]]))
    tails, vectors = region_arrows(SimpleNamespace(consistency=consistency))
    np.testing.assert_allclose(tails, [[9.7, 2.0], [4.0, 4.1]])
    np.testing.assert_allclose(vectors, [[0.3, 0.0], [0.0, -0.1]])
    np.testing.assert_allclose(tails + vectors, consistency.centre)
    assert region_arrows(SimpleNamespace(consistency=None))[0].shape == (0, 2)


def test_a_chosen_scale_is_kept_and_the_label_states_it():
    assert arrow_scale(SimpleNamespace(), 3.0) == 3.0
    assert arrow_label(5.0) == "displacement x5 (0.1 m drawn 0.5 m), truth to map"
