"""ROS map_server conventions on the command line: the threshold and negate options override a
YAML; a YAML beside an image that is not a map_server file is ignored, with one warning line,
when a resolution is given."""

from __future__ import annotations

import json
import re

import cv2
import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io import load_map

from .test_cli import SAMPLE, run

RESULTS_YAML = "quality: 0.93\nprecision: 0.88\nnote: scored by hand\n"


@pytest.mark.parametrize("text", [RESULTS_YAML, "{ not: yaml: at all\n", "- a list\n"])
def test_a_results_yaml_beside_an_image_is_ignored_given_a_resolution(text, tmp_path):
    png = tmp_path / "map.png"
    png.write_bytes((SAMPLE / "truth.png").read_bytes())
    (tmp_path / "map.yaml").write_text(text)
    with pytest.warns(UserWarning, match=r"map\.yaml: ignored, not a map_server YAML"):
        got = load_map(png, resolution=0.05)
    assert got.grid.resolution == 0.05 and got.grid.origin == (0.0, 0.0, 0.0)
    with pytest.raises(InputError, match=r"map\.yaml"):  # no resolution: still an error
        load_map(png)


def test_a_broken_map_server_yaml_still_stops_the_run(tmp_path):
    """A YAML that names an image is a map_server file: its mistakes are errors."""
    png = tmp_path / "map.png"
    png.write_bytes((SAMPLE / "truth.png").read_bytes())
    (tmp_path / "map.yaml").write_text("image: map.png\nresolution: -1\norigin: [0, 0, 0]\n")
    with pytest.raises(InputError, match="'resolution' must be positive"):
        load_map(png, resolution=0.05)


def test_results_yaml_warning_on_the_command_line(tmp_path):
    png = tmp_path / "map.png"
    png.write_bytes((SAMPLE / "truth.png").read_bytes())
    (tmp_path / "map.yaml").write_text(RESULTS_YAML)
    refused = run("eval", str(png), str(SAMPLE / "truth.png"))
    line, = refused.stderr.strip().splitlines()
    assert refused.returncode == 2 and "map.yaml: no 'image' key" in line
    proc = run("eval", str(png), str(SAMPLE / "truth.png"), "--map-resolution", "0.05",
               "--detectors", "hough", "--json", "-")
    assert proc.returncode == 0, proc.stderr
    warned = [ln for ln in proc.stderr.splitlines() if "warning" in ln]
    assert warned == [f"pcmapq: warning: {tmp_path / 'map.yaml'}: ignored, not a map_server "
                      "YAML (no 'image' key); map.png read with the resolution given, 0.05 m"]
    assert json.loads(proc.stdout)["alignment"]["fitness"] > 0.95


def test_negate_option_overrides_the_yaml(tmp_path):
    """The sample plan with its grey values inverted (walls white) and a YAML saying negate 0:
    read as it says, the rooms are walls (95 % of the cells occupied: refused, exit 1, as not a
    map of walls, pointing at negate); --map-negate reads the walls as walls, and the map then
    lies on the truth where it stands."""
    inverted = 255 - cv2.imread(str(SAMPLE / "truth.png"), cv2.IMREAD_GRAYSCALE)
    cv2.imwrite(str(tmp_path / "inv.png"), inverted)
    (tmp_path / "inv.yaml").write_text((SAMPLE / "truth.yaml").read_text().replace(
        "image: truth.png", "image: inv.png"))
    as_yaml = run("eval", str(tmp_path / "inv.png"), str(SAMPLE / "truth.png"), "--no-align",
                  "--detectors", "hough", "--json", "-")
    assert as_yaml.returncode == 1 and as_yaml.stdout == "", as_yaml.stderr
    share = re.search(r"not a map of walls: (\d+)% of its cells are occupied", as_yaml.stderr)
    assert share and int(share[1]) > 90, as_yaml.stderr
    assert "negate" in as_yaml.stderr
    negated = run("eval", str(tmp_path / "inv.png"), str(SAMPLE / "truth.png"), "--no-align",
                  "--map-negate", "--detectors", "hough", "--json", "-")
    assert negated.returncode == 0, negated.stderr
    doc = json.loads(negated.stdout)
    assert doc["distances"]["accuracy_m"]["max"] == 0.0
    assert doc["detectors"]["hough"]["quality"] == 1.0
    assert np.isclose(doc["coverage"], 1.0)
