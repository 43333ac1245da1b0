"""Same place or another place on real maps: the Intel map against its plan without force and
against Freiburg's plan, real plans against their maps and others', CARMEN buildings against
each other."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings, SourceConfig
from testkit.command import run_process as run
from testkit.paths import shared


def test_intel_map_against_its_plan_without_force():
    """The Intel SLAM map against its hand-drawn plan through the threshold options, no YAML
    and no --force: exit 0 (measured confidence 0.54: distinctiveness 0.108, recall 0.63)."""
    image, plan = shared("floorplans", "intel_map.png"), shared("floorplans", "lab_intel.png")
    proc = run("eval", str(image), str(plan), "--scale", "auto", "--truth-resolution", "0.05",
               "--map-occupied-thresh", "0.4", "--map-free-thresh", "0.05",
               "--detectors", "hough", "--json", "-")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["alignment"]["confidence"] >= 0.5


def test_intel_map_against_freiburgs_plan_is_refused():
    """Another building, scale free: exit 1 naming another place (measured confidence 0)."""
    image = shared("floorplans", "intel_map.png")
    plan = shared("floorplans", "Freiburg79_scan.png")
    proc = run("eval", str(image), str(plan), "--scale", "auto", "--truth-resolution", "0.05",
               "--map-occupied-thresh", "0.4", "--map-free-thresh", "0.05")
    assert proc.returncode == 1 and "another place" in proc.stderr, proc.stderr


PLAN = Settings(alignment=AlignmentConfig(scale=True),
                truth=SourceConfig(resolution=0.05),
                matching=MatchingConfig(detectors=()))


@pytest.mark.parametrize(("image", "plan", "same"), [
    (("floorplans", "freiburg_building79.png"), ("floorplans", "Freiburg79_scan.png"), True),
    (("halmstad", "maps", "KPT4A", "pseudo_occupancy", "KPT4A_01.png"),
     ("halmstad", "maps", "KPT4A", "layout", "KPT4A_layout.png"), True),
    (("halmstad", "maps", "HIH", "pseudo_occupancy", "HIH_01.png"),
     ("halmstad", "maps", "KPT4A", "layout", "KPT4A_layout.png"), False),
    (("floorplans", "freiburg_building79.png"), ("floorplans", "lab_intel.png"), False),
])
def test_real_plans_same_or_other_place(image, plan, same):
    """Measured confidence: Freiburg 079 1.0, KPT4A_01 1.0; HIH_01 on KPT4A's layout 0,
    Freiburg's map on Intel's plan 0."""
    forced = replace(PLAN, alignment=replace(PLAN.alignment, force=True))
    result = evaluate(shared(*image), shared(*plan), forced)
    assert (result.overlap.confidence >= 0.5) == same, result.overlap.confidence


def test_carmen_buildings_are_refused():
    """Two CARMEN buildings, both metric (rigid search): FHW's map on Intel's (measured
    confidence 0). Intel's on FHW's, scored alike, is the validation's case
    same-place-carmen-intel-vs-fhw, whose confidence tests/realdata/test_validation.py
    compares with its reference (0)."""
    intel = shared("carmen", "intel-corrected.log.gz")
    fhw = shared("carmen", "fhw-corrected.log.gz")
    result = evaluate(fhw, intel, Settings(matching=MatchingConfig(detectors=()),
                                           alignment=AlignmentConfig(force=True)))
    assert result.overlap.confidence < 0.5, result.overlap.confidence
