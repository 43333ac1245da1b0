"""Which settings of saved results ``pcmapq compare`` names as differing: those that change
what a figure means, with each value and its files; not a map's own source or pose guess, the
detectors chosen or a switch; a group a result has none of compared among the others."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from pcmapq.results.compare import Saved, check_same_settings, settings_differences
from pcmapq.settings import Settings

pytestmark = pytest.mark.unit


def saved(name: str, settings: dict) -> Saved:
    return Saved(Path(f"{name}.json"), name, {"settings": settings}, {})


@pytest.fixture
def base() -> dict:
    return Settings().to_dict()


def test_results_of_one_settings_agree(base):
    assert settings_differences([saved("a", base), saved("b", copy.deepcopy(base))]) == []
    assert check_same_settings([saved("a", base), saved("b", base)]) is None


def test_a_threshold_and_a_setting_not_recorded_are_named_with_their_files(base):
    other = copy.deepcopy(base)
    other["matching"]["threshold"] = 0.3
    old = copy.deepcopy(base)
    del old["structures"]["line_length"]
    differ = settings_differences([saved("a", base), saved("b", other), saved("c", old)])
    assert differ == ["matching.threshold (0.5 in a.json, c.json; 0.3 in b.json)",
                      "structures.line_length (1.5 in a.json, b.json; not recorded in c.json)"]


def test_a_maps_own_settings_the_detectors_and_switches_are_no_difference(base):
    other = copy.deepcopy(base)
    other["map"]["resolution"] = 0.1
    other["alignment"]["init"] = {"x_m": 1.0, "y_m": 2.0, "yaw_deg": 30.0, "scale": 1.0}
    other["matching"]["detectors"] = ["harris"]
    other["noref"]["enabled"] = not base["noref"]["enabled"]
    other["structures"]["enabled"] = False
    assert settings_differences([saved("a", base), saved("b", other)]) == []


def test_a_group_a_result_lacks_is_compared_among_the_others(base):
    """A result of a 2D map records no ``structures``: no difference with a 3D pair's; two
    3D pairs' structures still compare."""
    flat = copy.deepcopy(base)
    del flat["structures"], flat["map_3d"]
    other = copy.deepcopy(base)
    other["structures"]["line_length"] = 1.0
    assert settings_differences([saved("a", base), saved("b", flat)]) == []
    assert settings_differences([saved("a", base), saved("b", flat), saved("c", other)]) == \
        ["structures.line_length (1.5 in a.json; 1.0 in c.json)"]


def test_the_warning_names_three_and_counts_the_rest(base):
    other = copy.deepcopy(base)
    other["matching"]["threshold"] = 0.3
    other["raster"]["band_low"] = 0.2
    other["raster"]["band_high"] = 1.5
    other["footprint"]["margin"] = 0.1
    other["distances"]["taus"] = [0.1]
    line = check_same_settings([saved("a", base), saved("b", other)])
    assert line is not None and line.startswith("results scored with other settings: ")
    assert line.count(" in a.json") == 3 and line.endswith(
        " and 2 more settings; their figures may not compare"), line
