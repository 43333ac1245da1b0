"""Same place or another place: distinctiveness, confidence, the refusal and its message, and
map_server's thresholds on the command line. Synthetic known answers first, then real pairs."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pcmapq.align.coarse import Search, distinctiveness
from pcmapq.core.errors import EvaluationError
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.evaluation.same_place import confidence
from pcmapq.io import Thresholds, load_map
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings, SourceConfig
from pcmapq.testing import synth

from .conftest import in_map_frame, shared, write_image_map

SAMPLE = Path(__file__).resolve().parents[1] / "data" / "sample"
FAST = Settings(matching=MatchingConfig(detectors=()))


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pcmapq", *args], capture_output=True,
                          text=True, timeout=600)


# --- the rule ---------------------------------------------------------------------------------

def test_confidence_is_the_smaller_term():
    """min(distinct / 0.2, (recall - 0.4) / 0.4), clipped; no search: the recall term."""
    assert confidence(0.1, 0.6) == pytest.approx(0.5)
    assert confidence(0.05, 0.8) == pytest.approx(0.25)
    assert confidence(0.3, 0.7) == pytest.approx(0.75)
    assert confidence(None, 0.7) == pytest.approx(0.75)
    assert confidence(0.5, 1.0) == 1.0 and confidence(0.0, 1.0) == 0.0
    assert confidence(None, 0.2) == 0.0


def test_distinctiveness_of_known_scores():
    """Best score near the pose 0.8, best elsewhere 0.6 (turned by 90 degrees, or moved by a
    whole map radius): 1 - 0.6 / 0.8 = 0.25; a far pose scoring above the near one gives 0."""
    poses = np.array([[0.8, 0.0, 5.0, 5.0],    # at the pose
                      [0.7, 0.1, 5.2, 5.0],    # near it: 6 degrees, 0.2 m
                      [0.6, np.pi / 2, 5.0, 5.0],
                      [0.5, 0.0, 15.0, 5.0]])
    search = Search([], poses, np.zeros(2), 10.0)
    tf = Similarity2D(5.0, 5.0, 0.0)
    assert distinctiveness(search, tf) == pytest.approx(0.25)
    assert distinctiveness(search, Similarity2D(15.0, 5.0, 0.0)) == 0.0
    scaled = Search([], np.column_stack([poses, np.log([1.0, 1.0, 1.0, 1.0])]), np.zeros(2), 10)
    assert distinctiveness(scaled, tf) == pytest.approx(0.25)
    assert distinctiveness(scaled, Similarity2D(5.0, 5.0, 0.0, 1.5)) == 0.0  # other scale


# --- synthetic known answers ------------------------------------------------------------------

@pytest.mark.parametrize("scale", [False, True])
def test_building_against_itself_turned_is_confident(plan, truth_png, tmp_path, scale):
    """The synthetic building turned by 123 degrees and shifted: confidence 1 (measured:
    distinctiveness 0.3 rigid, 0.6 with the scale free; recall 1.0)."""
    tf = Similarity2D(3.0, -2.0, np.radians(123.0))
    path = write_image_map(in_map_frame(plan, tf), tmp_path / "turned.png")
    result = evaluate(path, truth_png, Settings(matching=MatchingConfig(detectors=()),
                                                alignment=AlignmentConfig(scale=scale)))
    assert result.overlap.confidence == 1.0
    assert result.alignment.distinctiveness > 0.2


@pytest.mark.parametrize("scale", [False, True])
def test_other_places_are_refused(truth_png, tmp_path, scale):
    """Round rooms and another seeded building (other room widths, other size) over the
    synthetic building: confidence below 0.5, rigid or with the scale free."""
    for name, segments in (("rooms", synth.round_rooms()),
                           ("other", synth.building_plan(7, 18.0, 20.0))):
        path = write_image_map(segments, tmp_path / f"{name}.png")
        settings = Settings(matching=MatchingConfig(detectors=()),
                            alignment=AlignmentConfig(scale=scale, force=True))
        result = evaluate(path, truth_png, settings)
        assert result.overlap.confidence < 0.5, (name, result.overlap)
        with pytest.raises(EvaluationError, match="likely cause"):
            evaluate(path, truth_png, Settings(matching=MatchingConfig(detectors=()),
                                               alignment=AlignmentConfig(scale=scale)))


def test_cli_exit_codes_and_refusal_messages(tmp_path):
    """The sample: exit 0; round rooms: exit 1 and one line naming the map, the confidence
    and --scale auto / --force; a wrong --init: exit 1 naming --init; the sample's plan drawn at
    twice its size read rigidly: exit 1 naming a scale that differs and --scale auto, exit 0
    with --scale auto."""
    truth = str(SAMPLE / "truth.png")
    ok = run("eval", str(SAMPLE / "scan.ply"), truth, "--detectors", "harris", "--json", "-")
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["alignment"]["confidence"] == 1.0

    rooms = write_image_map(synth.round_rooms(), tmp_path / "rooms.png")
    other = run("eval", str(rooms), truth)
    lines = other.stderr.strip().splitlines()
    assert other.returncode == 1 and len(lines) == 1 and "Traceback" not in other.stderr
    assert "rooms.png" in lines[0] and "confidence" in lines[0] and "--force" in lines[0]

    wrong = run("eval", truth, truth, "--init", "4,3,90", "--detectors", "harris")
    assert wrong.returncode == 1 and "--init" in wrong.stderr, wrong.stderr

    big = tmp_path / "big.png"
    big.write_bytes((SAMPLE / "truth.png").read_bytes())
    yaml = (SAMPLE / "truth.yaml").read_text().replace("image: truth.png", "image: big.png")
    (tmp_path / "big.yaml").write_text(yaml.replace("resolution: 0.05", "resolution: 0.1"))
    scaled = run("eval", str(big), truth, "--detectors", "harris")
    assert scaled.returncode == 1 and "scale that differs" in scaled.stderr, scaled.stderr
    assert "--scale auto" in scaled.stderr
    auto = run("eval", str(big), truth, "--scale", "auto", "--detectors", "harris")
    assert auto.returncode == 0, auto.stderr


# --- map_server thresholds on the command line ------------------------------------------------

def test_thresholds_override_the_yaml(tmp_path):
    """Grey 127 (p = 0.50) and 230 (p = 0.10): unknown and free by ROS's defaults; occupied
    and unknown with occupied 0.4, free 0.05; negate reads v / 255 (127: p 0.498, 230: 0.90)."""
    import cv2

    cv2.imwrite(str(tmp_path / "m.png"), np.array([[127, 230, 0]], dtype=np.uint8))
    (tmp_path / "m.yaml").write_text("image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                     "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    state = load_map(tmp_path / "m.png").state
    assert state.tolist() == [[UNKNOWN, FREE, OCCUPIED]]
    state = load_map(tmp_path / "m.png", thresholds=Thresholds(0.4, 0.05)).state
    assert state.tolist() == [[OCCUPIED, UNKNOWN, OCCUPIED]]
    state = load_map(tmp_path / "m.yaml", thresholds=Thresholds(negate=True)).state
    assert state.tolist() == [[UNKNOWN, OCCUPIED, FREE]]


@pytest.mark.parametrize("option", ["--map-free-thresh", "--truth-occupied-thresh"])
def test_threshold_options_are_probabilities(option):
    """Outside [0, 1]: a usage error, exit 2, no traceback."""
    truth = str(SAMPLE / "truth.png")
    proc = run("eval", truth, truth, option, "1.5")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert option in proc.stderr


@pytest.mark.parametrize("side", ["map", "truth"])
def test_threshold_options_reach_their_side(side, tmp_path):
    """--map-occupied-thresh 1 leaves the map no occupied cell, --truth-occupied-thresh 1 the
    truth: exit 2 naming that file, the other side read as before."""
    map_png = tmp_path / "map.png"
    map_png.write_bytes((SAMPLE / "truth.png").read_bytes())
    (tmp_path / "map.yaml").write_text(
        (SAMPLE / "truth.yaml").read_text().replace("image: truth.png", "image: map.png"))
    proc = run("eval", str(map_png), str(SAMPLE / "truth.png"), f"--{side}-occupied-thresh", "1")
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert f"{side}.png: no occupied cells" in lines[0]


# --- real pairs -------------------------------------------------------------------------------

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
    """Two CARMEN buildings, both metric (rigid search): Intel's map on FHW's, and back
    (measured confidence 0.09, 0)."""
    intel = shared("carmen", "intel-corrected.log.gz")
    fhw = shared("carmen", "fhw-corrected.log.gz")
    for a, b in ((intel, fhw), (fhw, intel)):
        result = evaluate(a, b, Settings(matching=MatchingConfig(detectors=()),
                                         alignment=AlignmentConfig(force=True)))
        assert result.overlap.confidence < 0.5, (a.name, b.name, result.overlap.confidence)
