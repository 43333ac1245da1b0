"""The settings of two 3D clouds' figures (AWD, SCS, the 3D consistency map's tile) are recorded
only by results that have those figures, so the results of other inputs stay as they were."""

from __future__ import annotations

from dataclasses import replace

from pcmapq.evaluation.scoring import recorded_settings
from pcmapq.settings import Settings


def test_the_3d_group_is_recorded_only_with_3d_figures():
    given = replace(Settings(), map_3d=replace(Settings().map_3d, tile=12.0))
    assert "map_3d" not in recorded_settings(given, False, False)
    assert recorded_settings(given, True, True)["map_3d"]["tile"] == 12.0
    assert Settings.from_dict(recorded_settings(given, True, True)) == given
    assert Settings.from_dict(recorded_settings(Settings(), False, False)).map_3d.tile == 8.0
