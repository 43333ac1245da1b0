"""Same place or another place on the command line: exit codes and the refusal's message, and
map_server's thresholds as options (probabilities, each reaching its side)."""

from __future__ import annotations

import json

import numpy as np
import open3d as o3d
import pytest

from testkit import synth
from testkit.command import run_process as run
from testkit.files import write_image_map
from testkit.paths import SAMPLE


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


def test_a_map_hung_off_its_truth_by_the_given_frame_is_refused(tmp_path):
    """The sample placed 14 m off its plan by a wrong --init: its outer wall still lies on the
    plan's, where the two meet, but it covers 19 % of the plan and 12 % of it lies on the plan:
    exit 1, one line naming those shares and the given frame; its right pose, partial or
    whole, is the same place."""
    truth, scan = str(SAMPLE / "truth.png"), str(SAMPLE / "scan.ply")
    off = run("eval", scan, truth, "--init", "6,-6,37", "--detectors", "harris")
    lines = off.stderr.strip().splitlines()
    assert off.returncode == 1 and len(lines) == 1 and "Traceback" not in off.stderr
    assert "it covers 19% of the truth and 12% of it lies on the truth's walls" in lines[0]
    assert "the given frame" in lines[0] and "--init" in lines[0]
    points = np.asarray(o3d.io.read_point_cloud(scan).points)
    left = points[:, 0] < np.quantile(points[:, 0], 0.2)
    np.save(tmp_path / "part.npy", points[left])
    for cloud, covers in ((scan, 0.9), (str(tmp_path / "part.npy"), 0.05)):
        right = run("eval", cloud, truth, "--init", "6,8,37", "--detectors", "harris",
                    "--json", "-")
        assert right.returncode == 0, right.stderr
        doc = json.loads(right.stdout)
        assert doc["alignment"]["confidence"] == 1.0 and doc["coverage"] > covers
