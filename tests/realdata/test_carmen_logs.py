"""Real CARMEN logs of ../shared/data/carmen: their extent, a log scored against itself, and drift
ladders ranking maps by how much their poses drifted (skipped, saying why, where absent)."""

from __future__ import annotations

import numpy as np

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import load_map
from pcmapq.settings import AlignmentConfig, Settings
from testkit import drift
from testkit.paths import shared


def test_intel_log() -> None:
    """Intel Research Lab, Seattle: a building about 29 m square."""
    log = shared("carmen", "intel-corrected.log.gz")
    cloud = load_map(log)
    assert 150_000 < len(cloud.points) < 165_000
    low, high = np.percentile(cloud.points[:, :2], [1, 99], axis=0)
    assert ((high - low > 24.0) & (high - low < 31.0)).all(), high - low


def test_intel_log_against_itself() -> None:
    log = shared("carmen", "intel-corrected.log.gz")
    result = evaluate(log, log)
    for name, det in result.detectors.items():
        assert det.matching.quality >= 0.95, name
        assert det.matching.precision >= 0.95, name


def test_drift_ranks_maps() -> None:
    """Orebro's first 80 scans, readings up to 10 m (about 3 s): the map along a drifted
    trajectory (4 % gain errors) scores worse than the corrected one on every detector's
    quality and precision and on the distance figures."""
    log = shared("carmen", "orebro-corrected.log.gz")
    none, large = drift.ladder(log, levels=(0.0, 0.04), max_range=10.0,
                               settings=Settings(alignment=AlignmentConfig(force=True)), scans=80)
    for name in none.quality:
        assert large.quality[name] < none.quality[name], name
        assert large.precision[name] < none.precision[name], name
    assert large.f_at_01 < none.f_at_01
    assert large.accuracy_mean_m > none.accuracy_mean_m


def test_drift_ladder_every_f1_falls_and_sift_quality_with_it():
    """Orebro's first 180 scans, readings up to 10 m, at 1, 2 and 4 % drift (pose errors about
    2.6, 5.2 and 10.4 m; about 10 s): every detector's f1 falls at every step, and SIFT's
    quality falls below 0.6 at 4 % (it saturated near 0.8 when any keypoint within the
    threshold matched, however unlike its descriptor)."""
    log = shared("carmen", "orebro-corrected.log.gz")
    rungs = drift.ladder(log, levels=(0.01, 0.02, 0.04), max_range=10.0,
                         settings=Settings(alignment=AlignmentConfig(force=True)), scans=180)
    assert drift.not_falling(rungs) == []
    for name in rungs[0].f1:
        values = [r.f1[name] for r in rungs]
        assert all(b < a for a, b in zip(values, values[1:], strict=False)), (name, values)
    assert rungs[-1].quality["sift"] < 0.6
    assert rungs[-1].pose_error_m > 10.0
