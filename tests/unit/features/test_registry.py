"""The detectors' registry: one table (pcmapq.features.names.DETECTOR_SOURCES) names every
detector, in the order the docs and the JSON report list them; nothing else is run."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path

import numpy as np

import pcmapq.features as features
from pcmapq.features import registry
from pcmapq.features.names import DEFAULT_DETECTORS, DETECTOR_NAMES, DETECTOR_SOURCES
from pcmapq.match import match
from testkit import synth

DOCS = Path(__file__).resolve().parents[3] / "docs"

#: A Harris detector of a wider window under another name, as a module of its own.
CORNERS_AGAIN = (
    "from dataclasses import dataclass\n"
    "from pcmapq.features import harris\n"
    "from pcmapq.features.base import Detector\n"
    "@dataclass(frozen=True)\n"
    "class Params(harris.Params):\n"
    "    radius: float = 0.6\n"
    "DETECTOR = Detector('corners_again', harris.detect, harris.candidates, Params)\n")


def test_the_registry_lists_the_detectors_the_docs_name_in_their_order():
    """The JSON schema (docs/formats.md), the figures' colours and the --detectors error
    (docs/errors.md) list the registry's detectors, in its order."""
    assert tuple(registry.DETECTORS) == DETECTOR_NAMES == tuple(DETECTOR_SOURCES)
    assert DEFAULT_DETECTORS == tuple(n for n, d in registry.DETECTORS.items() if d.by_default)
    formats = (DOCS / "formats.md").read_text()
    schema = re.search(r'"detectors": \{((?:"\w+"\|?)+):', formats)
    assert schema and tuple(re.findall(r'"(\w+)"', schema.group(1))) == DETECTOR_NAMES
    colours = re.search(r"colour-vision deficiency: ([^.]+)", formats.replace("\n", " "))
    assert colours and tuple(c.split()[0] for c in colours.group(1).split(", ")) \
        == DETECTOR_NAMES
    errors = (DOCS / "errors.md").read_text()
    assert f"unknown detector(s) ...; choose from {','.join(DETECTOR_NAMES)}`" in errors


def test_a_module_beside_the_detectors_is_not_picked_up(tmp_path, monkeypatch):
    """A module of pcmapq.features defining a DETECTOR but not named in the registry is never
    loaded nor run: the registry built afresh holds the listed detectors only."""
    (tmp_path / "corners_again.py").write_text(CORNERS_AGAIN)
    monkeypatch.setattr(features, "__path__", [*features.__path__, str(tmp_path)])
    monkeypatch.delitem(sys.modules, "pcmapq.features.corners_again", raising=False)
    spec = importlib.util.spec_from_file_location("fresh_registry", registry.__file__)
    fresh = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fresh)
    assert tuple(fresh.DETECTORS) == DETECTOR_NAMES
    assert "pcmapq.features.corners_again" not in sys.modules


def test_a_detector_is_one_line_of_the_registry(tmp_path, monkeypatch):
    """A detector named in a registry is loaded, run with its own parameters and matched by
    name; a registry naming something that is not that Detector is refused."""
    (tmp_path / "corners_again_module.py").write_text(CORNERS_AGAIN)
    monkeypatch.syspath_prepend(str(tmp_path))
    found = registry.load({**DETECTOR_SOURCES,
                           "corners_again": "corners_again_module:DETECTOR"})
    assert tuple(found) == (*DETECTOR_NAMES, "corners_again")
    monkeypatch.setitem(features.DETECTORS, "corners_again", found["corners_again"])
    assert features.default_params()["corners_again"].radius == 0.6
    plan = synth.building_plan(0)
    grid = synth.plan_grid(plan, 0.05)
    occ = synth.render(plan, grid) == synth.OCCUPIED
    f = features.detect("corners_again", occ, grid)
    m = match("corners_again", f, f)
    assert f.strong.sum() >= 10 and m.quality == 1.0
    wide = features.detect("harris", occ, grid, features.harris.Params(radius=0.6))
    np.testing.assert_array_equal(f.xy, wide.xy)
    for wrong in ("pcmapq.features.harris:DETECTOR", "pcmapq.features.harris:Params"):
        try:
            registry.load({"corners_again": wrong})
        except TypeError as e:
            assert "is not the Detector 'corners_again'" in str(e)
        else:
            raise AssertionError(f"{wrong} was taken for corners_again")
