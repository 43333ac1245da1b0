"""The Result's JSON of whole evaluations: a 3D registration in the frame chain and back, and the
threshold of a result without detectors read back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.results.result import Result
from pcmapq.settings import Settings
from testkit.paths import SAMPLE
from testkit.reference import same_document


def test_a_3d_registration_in_the_chain_and_back(tmp_path: Path):
    """Both sides 3D clouds, the map turned 30 degrees and moved (3, -2) m: the reported
    map -> truth transform is that pose, and the 3D registration and both levellings survive
    the round trip."""
    from pcmapq.io.writers import write_cloud
    from testkit import synth

    cloud = synth.lidar_cloud(synth.building_plan(0))
    yaw, t = np.radians(30.0), np.array([3.0, -2.0, 0.0])
    rot = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    write_cloud(tmp_path / "truth.ply", cloud)
    write_cloud(tmp_path / "map.ply", (cloud[::2] - t) @ rot)  # p_truth = R p_map + t
    r = evaluate(tmp_path / "map.ply", tmp_path / "truth.ply")
    doc = r.to_dict()
    assert doc["alignment"]["method"] == "3d"
    assert doc["alignment"]["yaw_deg"] == pytest.approx(30.0, abs=0.2)
    assert (doc["alignment"]["x_m"], doc["alignment"]["y_m"]) == pytest.approx((3, -2), abs=0.05)
    assert doc["frames"]["registration_3d"] is not None
    assert doc["frames"]["map_levelling"] is not None
    assert doc["frames"]["truth_levelling"] is not None
    back = Result.from_json(r.to_json())
    assert not same_document(back, r)
    np.testing.assert_allclose(back.registration_3d.transform, r.registration_3d.transform,
                               atol=1e-6)


def test_a_result_without_detectors_keeps_its_threshold_when_read_back():
    """The matching threshold of a result whose detectors were all left out comes back from
    its settings (it fell back to 0.5: the settings' threshold was looked for at the top)."""
    from pcmapq.settings import MatchingConfig

    sample = SAMPLE
    result = evaluate(sample / "scan.ply", sample / "truth.png",
                      Settings(matching=MatchingConfig(detectors=(), threshold=0.3)))
    assert result.detectors == {}
    assert Result.from_json(result.to_json()).threshold == 0.3
