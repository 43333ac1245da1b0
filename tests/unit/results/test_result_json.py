"""The Result's JSON: one statistics type for every figure, the frame chain, and from_json
reading back what to_json wrote, older results (without the noref block) too."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pcmapq.core.stats import FIELDS, Stats
from pcmapq.results.result import Result
from pcmapq.settings import (
    Settings,
)
from testkit.reference import same_document


@pytest.fixture(scope="module")
def result(sample_result) -> Result:
    return sample_result


def test_stats_of_known_lengths():
    s = Stats.of(np.array([3.0, 4.0]))
    assert s == Stats(2, 3.5, 3.5, pytest.approx(np.sqrt(12.5)), 0.5, 3.0, 4.0,
                      pytest.approx(3.95))
    assert list(s.to_dict()) == list(FIELDS)
    assert Stats.from_dict(s.to_dict()) == s


@pytest.mark.parametrize("values", [np.empty(0), np.array([0.1, np.inf])])
def test_stats_with_nothing_to_measure_are_undefined(values):
    s = Stats.of(values)
    assert s.count == len(values)
    assert all(getattr(s, k) is None for k in FIELDS if k != "count")


def test_every_figure_uses_the_one_statistics_type(result: Result):
    doc = result.to_dict()
    for stats in (doc["distances"]["accuracy_m"], doc["distances"]["completeness_m"],
                  *(d["displacement_m"] for d in doc["detectors"].values())):
        assert list(stats) == list(FIELDS)
    harris = doc["detectors"]["harris"]
    lengths = [m["displacement_m"] for m in doc["matches"] if m["detector"] == "harris"]
    assert harris["displacement_m"]["count"] == len(lengths)
    assert harris["displacement_m"]["max"] == pytest.approx(max(lengths), abs=1e-6)
    assert harris["displacement_m"]["std"] == pytest.approx(np.std(lengths), abs=1e-6)


def test_counts_add_up(result: Result):
    """matched (truth side) and matched_map (map side) recompute quality and precision."""
    doc = result.to_dict()
    for name, det in doc["detectors"].items():
        assert det["quality"] == pytest.approx(det["matched"] / det["truth_features"], abs=1e-6)
        assert det["precision"] == pytest.approx(det["matched_map"] / det["map_features"],
                                                 abs=1e-6)
        counted = [m["counted"] for m in doc["matches"] if m["detector"] == name]
        assert sum(c["truth"] for c in counted) == det["matched"]
        assert sum(c["map"] for c in counted) == det["matched_map"]


def test_the_figures_alone_are_the_document_without_its_feature_lists(result: Result):
    whole, figures = result.to_dict(), result.to_dict(features=False)
    assert all(whole[key] for key in ("matches", "missing", "extra"))
    assert figures == {**whole, "matches": [], "missing": [], "extra": []}


def test_the_frame_chain_is_reported(result: Result):
    """The sample scan is a level 3D cloud: its plan comes from levelling it, with no tilt; the
    truth is an image (no levelling); the planar transform is the reported alignment."""
    frames = result.to_dict()["frames"]
    assert frames["convention"] == "p_truth = s * R(yaw) * p_map + t"
    assert frames["truth_levelling"] is None and frames["registration_3d"] is None
    assert frames["map_levelling"]["tilt_deg"] < 0.5
    assert np.allclose(frames["map_levelling"]["matrix"], np.eye(3), atol=0.01)
    a = result.to_dict()["alignment"]
    assert {k: frames["planar"][k] for k in ("x_m", "y_m", "yaw_deg", "scale")} == \
        {k: a[k] for k in ("x_m", "y_m", "yaw_deg", "scale")}


def test_from_json_reads_back_what_to_json_wrote(result: Result):
    back = Result.from_json(result.to_json())
    assert not same_document(back, result)
    # field for field: what the JSON holds is what the Result holds (rounded to 1e-6)
    assert back.grid.shape == result.grid.shape and back.grid.resolution == result.grid.resolution
    np.testing.assert_allclose(back.grid.origin, result.grid.origin, atol=1e-6)
    assert back.alignment.method == result.alignment.method
    for field in ("fitness", "rmse_m", "tolerance_m", "distinctiveness"):
        assert getattr(back.alignment, field) == pytest.approx(
            getattr(result.alignment, field), abs=1e-6)
    np.testing.assert_allclose(back.alignment.transform.matrix,
                               result.alignment.transform.matrix, atol=1e-5)
    assert back.distances.accuracy.to_dict() == pytest.approx(
        result.distances.accuracy.to_dict(), abs=1e-6)
    for name, det in result.detectors.items():
        got = back.detectors[name]
        assert got.matching.quality == pytest.approx(det.matching.quality, abs=1e-6)
        assert got.matching.matched_map == det.matching.matched_map
        np.testing.assert_allclose(got.truth_xy, det.truth_xy, atol=1e-6)
        np.testing.assert_allclose(got.matching.displacement, det.matching.displacement,
                                   atol=2e-6)
    assert back.settings == json.loads(json.dumps(result.settings))
    assert back.truth_occupied is None  # rasters are not in the JSON


def test_settings_read_back_from_their_dict():
    from dataclasses import replace

    from pcmapq.core.transform import Similarity2D
    from pcmapq.features import harris
    from pcmapq.io import Thresholds
    from pcmapq.settings import AlignmentConfig, SourceConfig

    s = Settings(map=SourceConfig(0.1, Thresholds(0.4, 0.05, None)),
                 alignment=AlignmentConfig(init=Similarity2D(1.0, 2.0, 0.5), scale=True))
    s = replace(s, matching=replace(s.matching, params={"harris": harris.Params(sigma=0.2)}))
    back = Settings.from_dict(json.loads(json.dumps(s.to_dict())))
    assert back.to_dict() == s.to_dict()
    assert back.alignment.init.yaw == pytest.approx(0.5)
    assert back.matching.params["harris"] == harris.Params(sigma=0.2)


def test_older_results_read_back_without_noref():
    doc = Settings().to_dict()
    del doc["noref"]
    assert Settings.from_dict(doc).noref.enabled is False


def test_from_json_reads_a_path_or_the_text(result: Result, tmp_path):
    """A path (str or Path) is read; text starting with '{' is parsed: the same Result."""
    path = tmp_path / "full.json"
    path.write_text(result.to_json())
    text = Result.from_json(result.to_json()).to_json()
    assert Result.from_json(path).to_json() == text
    assert Result.from_json(str(path)).to_json() == text
    assert Result.from_json("\n  " + result.to_json()).to_json() == text
    with pytest.raises(FileNotFoundError):
        Result.from_json(str(tmp_path / "absent.json"))
