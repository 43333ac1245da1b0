"""Same place or another place, synthetic known answers through the library: a building against
itself turned is confident, other places are refused (the rule: tests/unit/evaluation; the
command line: tests/cli/test_same_place.py; real pairs: tests/realdata/test_same_place.py)."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.errors import EvaluationError
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from testkit import synth
from testkit.files import in_map_frame, write_image_map

FAST = Settings(matching=MatchingConfig(detectors=()))


# --- synthetic known answers ------------------------------------------------------------------

@pytest.mark.parametrize("scale", [False, True])
def test_building_against_itself_turned_is_confident(plan, truth_png, tmp_path, scale):
    """The synthetic building turned by 123 degrees and shifted: confidence 1 (measured:
    distinctiveness 0.3 rigid, 0.6 with the scale free; recall 1.0)."""
    tf = Similarity2D(3.0, -2.0, np.radians(123.0))
    path = write_image_map(in_map_frame(plan, tf), tmp_path / "turned.png")
    result = evaluate(path, truth_png, Settings(matching=MatchingConfig(detectors=()),
                                                alignment=AlignmentConfig(scale=scale)))
    assert result.overlap.confidence == 1.0
    assert result.alignment.distinctiveness > 0.2


@pytest.mark.parametrize("scale", [False, True])
def test_other_places_are_refused(truth_png, tmp_path, scale):
    """Round rooms and another seeded building (other room widths, other size) over the
    synthetic building: confidence below 0.5, rigid or with the scale free."""
    for name, segments in (("rooms", synth.round_rooms()),
                           ("other", synth.building_plan(7, 18.0, 20.0))):
        path = write_image_map(segments, tmp_path / f"{name}.png")
        settings = Settings(matching=MatchingConfig(detectors=()),
                            alignment=AlignmentConfig(scale=scale, force=True))
        result = evaluate(path, truth_png, settings)
        assert result.overlap.confidence < 0.5, (name, result.overlap)
        with pytest.raises(EvaluationError, match="likely cause"):
            evaluate(path, truth_png, Settings(matching=MatchingConfig(detectors=()),
                                               alignment=AlignmentConfig(scale=scale)))
