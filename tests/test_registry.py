"""One source of truth: the command line's defaults are Settings', and a detector is one file."""

from __future__ import annotations

import pytest
import typer

import pcmapq.features as features
from pcmapq import synth
from pcmapq.cli import app
from pcmapq.config import DETECTOR_NAMES, Settings
from pcmapq.match import match


def test_cli_defaults_are_the_settings_defaults():
    eval_command = typer.main.get_command(app).commands["eval"]
    defaults = {p.name: p.default for p in eval_command.params}
    s = Settings()
    assert defaults["threshold"] == s.matching.threshold
    assert (defaults["band_low"], defaults["band_high"]) == (s.raster.band_low,
                                                             s.raster.band_high)
    assert defaults["voxel_3d"] == s.alignment.voxel_3d
    assert defaults["footprint"] == s.footprint.rule
    assert defaults["detectors"] == ",".join(s.matching.detectors) == ",".join(DETECTOR_NAMES)
    assert tuple(float(t) for t in defaults["tau"].split(",")) == s.distances.taus


def test_a_detector_is_one_file(tmp_path, monkeypatch):
    """A module dropped beside the detectors is found, run and matched by name."""
    (tmp_path / "corners_again.py").write_text(
        "from pcmapq.features.base import Detector\n"
        "from pcmapq.features.harris import candidates, detect\n"
        "DETECTOR = Detector('corners_again', detect, candidates)\n")
    monkeypatch.setattr(features, "__path__", [*features.__path__, str(tmp_path)])
    found = features._discover()
    assert "corners_again" in found and set(DETECTOR_NAMES) <= set(found)
    monkeypatch.setitem(features.DETECTORS, "corners_again", found["corners_again"])
    plan = synth.building_plan(0)
    grid = synth.plan_grid(plan, 0.05)
    occ = synth.render(plan, grid) == synth.OCCUPIED
    f = features.detect("corners_again", occ, grid)
    m = match("corners_again", f, f)
    assert f.strong.sum() >= 10 and m.quality == 1.0


def test_an_unknown_detector_is_refused():
    with pytest.raises(Exception, match="unknown feature detector"):
        features.detect_in("nope", None)
