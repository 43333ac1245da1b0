"""The result's block of 3D structures (``structures_3d``): written as the schema declares it,
read back, named as figures; and absent, with its settings, from a 2D result."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from pcmapq.results.figures import by_name
from pcmapq.results.result import Result
from pcmapq.results.rows import head
from pcmapq.results.schema import ResultDocument
from testkit.building3d import known_structures


@pytest.fixture(scope="module")
def result(sample_result) -> Result:
    """The sample's result holding the structures of the synthetic building's moved map."""
    return replace(sample_result, structures=known_structures())


def test_a_2d_result_has_no_structures_nor_their_settings(sample_result):
    doc = sample_result.to_dict()
    assert "structures_3d" not in doc and "structures" not in doc["settings"]
    assert all(v is None for k, v in sample_result.figures().items()
               if k.split(".")[0] in ("planes", "plane_lines"))


def test_the_block_holds_each_detectors_scores_and_structures(result):
    doc = result.to_dict()
    block = doc["structures_3d"]
    ResultDocument.model_validate(doc)
    assert list(block) == ["planes", "plane_lines", "fit"]
    assert block["fit"]["applied"] is True and block["fit"]["planes_matched"] == 18
    planes = block["planes"]
    assert (planes["quality"], planes["precision"], planes["f1"]) == (1.0, 1.0, 1.0)
    assert planes["truth_structures"] == planes["matched"] == len(planes["matches"]) == 18
    assert (planes["max_angle_deg"], planes["max_offset_m"]) == (5.0, 0.5)
    moved = sorted(m["displacement_m"] for m in planes["matches"])
    assert moved[-1] == pytest.approx(0.30, abs=0.02)
    assert moved[-2] == pytest.approx(0.05, abs=0.01)
    assert planes["displacement_m"]["max"] == pytest.approx(moved[-1], abs=1e-6)
    wall = next(m for m in planes["matches"] if m["displacement_m"] == moved[-1])
    assert wall["truth"]["normal"] == pytest.approx([1, 0, 0], abs=0.01)
    assert wall["map"]["offset_m"] - wall["truth"]["offset_m"] == pytest.approx(0.3, abs=0.02)
    assert len(wall["truth"]["corners_m"]) == 4 and wall["truth"]["area_m2"] > 10
    line = block["plane_lines"]["matches"][0]
    assert set(line) == {"truth", "map", "displacement_m", "angle_deg"}
    assert set(line["truth"]) == {"direction", "point_m", "length_m"}


def test_the_figures_alone_leave_the_lists_empty(result):
    whole, figures = result.to_dict()["structures_3d"], result.to_dict(False)["structures_3d"]
    for name in ("planes", "plane_lines"):
        assert figures[name] == {**whole[name], "matches": [], "missing": [], "extra": []}


def test_the_block_reads_back(result):
    back = Result.from_json(result.to_json())
    assert back.structures.max_angle == 5.0 and back.structures.max_offset == 0.5
    for name, found in result.structures.detectors.items():
        got = back.structures.detectors[name]
        m, g = found.matching, got.matching
        assert (g.quality, g.precision, g.f1, g.matched) == (m.quality, m.precision, m.f1,
                                                             m.matched)
        np.testing.assert_allclose(g.displacement, m.displacement, atol=1e-6)
        np.testing.assert_allclose(g.angle, m.angle, atol=1e-6)
        assert len(got.truth) == m.truth_structures and len(got.map) == m.map_structures
    fit, was = back.structures.fit, result.structures.fit
    np.testing.assert_allclose(fit.matrix, was.matrix, atol=1e-6)
    assert (fit.applied, fit.held, fit.pairs) == (was.applied, was.held, was.pairs)
    planes = back.structures.detectors["planes"]
    first = result.structures.detectors["planes"]
    k = int(first.matching.truth_idx[0])
    np.testing.assert_allclose(planes.truth.corners[0], first.truth.corners[k], atol=1e-6)
    again = json.loads(Result.from_json(result.to_json()).to_json())["structures_3d"]
    assert again["planes"]["matches"] == json.loads(result.to_json())["structures_3d"][
        "planes"]["matches"]


def test_the_structures_figures_are_named_and_columns(result):
    figures = result.figures()
    assert figures["planes.quality"] == figures["planes.f1"] == 1.0
    assert figures["planes.displacement.max"] == pytest.approx(0.30, abs=0.02)
    assert figures["plane_lines.angle.max"] < 1.0
    assert by_name()["planes.displacement.max"].unit == "m"
    columns = head()
    assert {"planes_quality", "planes_precision", "planes_f1", "plane_lines_f1"} <= set(columns)
    assert columns.index("planes_quality") == columns.index("rooms_f1") + 1
