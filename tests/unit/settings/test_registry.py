"""One source of truth: the command line's defaults are Settings', and the names the help reads
without loading a detector are the registry's (a detector is one line of it:
tests/unit/features/test_registry.py)."""

from __future__ import annotations

from dataclasses import FrozenInstanceError, asdict, replace

import numpy as np
import pytest
import typer

import pcmapq.features as features
from pcmapq.cli import app
from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.features import registry
from pcmapq.match import match
from pcmapq.settings import DETECTOR_NAMES, Settings
from testkit import synth


def test_cli_defaults_are_the_settings_defaults():
    eval_command = typer.main.get_command(app).commands["eval"]
    defaults = {p.name: p.default for p in eval_command.params}
    s = Settings()
    assert defaults["threshold"] == s.matching.threshold
    assert (defaults["band_low"], defaults["band_high"]) == (s.raster.band_low,
                                                             s.raster.band_high)
    assert defaults["voxel_3d"] == s.alignment.voxel_3d
    assert defaults["footprint"] == s.footprint.rule
    assert defaults["detectors"] == ",".join(s.matching.detectors) == \
        ",".join(features.DEFAULT_DETECTORS)
    assert set(features.DEFAULT_DETECTORS) == set(DETECTOR_NAMES)
    assert tuple(float(t) for t in defaults["tau"].split(",")) == s.distances.taus


def test_the_names_read_without_the_detectors_are_the_registrys():
    """pcmapq.features.names (read by the settings and the help) lists the registry's
    detectors in its order, and those run by default."""
    assert features.DETECTOR_NAMES == tuple(registry.DETECTORS)
    assert features.DEFAULT_DETECTORS == tuple(
        name for name, d in registry.DETECTORS.items() if d.by_default)


def test_parameters_are_data():
    """Every detector's defaults are a frozen dataclass of plain numbers; None means them.
    default_params holds those of the detectors run by default."""
    assert set(features.default_params()) == set(features.DEFAULT_DETECTORS)
    defaults = {name: d.params() for name, d in features.DETECTORS.items()}
    assert set(defaults) == set(DETECTOR_NAMES)
    for name, params in defaults.items():
        assert params == features.DETECTORS[name].params()
        assert all(isinstance(v, int | float) for v in asdict(params).values()), name
        with pytest.raises(FrozenInstanceError):
            params.threshold = 1.0
    plan = synth.building_plan(0)
    grid = synth.plan_grid(plan, 0.05)
    occ = synth.render(plan, grid) == synth.OCCUPIED
    walls = features.walls_of(occ, grid)
    for name, params in defaults.items():
        np.testing.assert_array_equal(features.detect_in(name, walls).xy,
                                      features.detect_in(name, walls, params).xy)
    stricter = features.detect_in("harris", walls, replace(defaults["harris"], threshold=2e-4))
    assert 0 < stricter.strong.sum() < features.detect_in("harris", walls).strong.sum()


def test_another_detectors_parameters_are_refused():
    harris = features.default_params()["harris"]
    with pytest.raises(InputError, match="takes pcmapq.features.sift.Params"):
        features.detect("sift", np.zeros((20, 20), bool), MetricGrid(0.05, (0, 0, 0), (20, 20)),
                        harris)
    with pytest.raises(InputError, match="takes pcmapq.features.hough.Params"):
        match("hough", features.base.empty_features(), features.base.empty_features(), 0.5,
              harris)


def test_an_unknown_detector_is_refused():
    with pytest.raises(Exception, match="unknown feature detector"):
        features.detect_in("nope", None)
