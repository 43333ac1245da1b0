"""ROS map_server conventions on the command line: the threshold and negate options override a
YAML; a YAML beside an image that is not a map_server file is ignored, with one warning line,
when a resolution is given, and so is a YAML that names another image; a YAML value that is no
number is one error line."""

from __future__ import annotations

import json
import re
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from testkit.command import run
from testkit.files import sample_yaml, write_png
from testkit.paths import SAMPLE

RESULTS_YAML = "quality: 0.93\nprecision: 0.88\nnote: scored by hand\n"


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


@pytest.mark.unit
def test_yaml_non_number_through_the_cli_is_one_line(tmp_path: Path):
    path = sample_yaml(tmp_path, resolution="5cm")
    got = CliRunner().invoke(app, ["eval", str(path), str(path)])
    assert got.exit_code == 2, got.output
    line, = got.stderr.strip().splitlines()
    assert "m.yaml" in line and "'resolution' must be a finite number" in line


@pytest.mark.parametrize("quiet", [[], ["--quiet"]])
def test_yaml_naming_another_image_warning_on_the_command_line(tmp_path: Path,
                                                               quiet: list[str]) -> None:
    """One line on stderr (--quiet too: it keeps warnings); stdout's --json - stays JSON."""
    (tmp_path / "a.png").write_bytes((SAMPLE / "truth.png").read_bytes())
    write_png(tmp_path / "b.png", 255 - cv2.imread(str(SAMPLE / "truth.png"), 0))
    (tmp_path / "a.yaml").write_text((SAMPLE / "truth.yaml").read_text().replace(
        "image: truth.png", "image: b.png"))
    got = run("eval", str(tmp_path / "a.png"), str(SAMPLE / "truth.png"), "--detectors",
              "hough", "--json", "-", *quiet)
    assert got.returncode == 0, got.stderr
    assert got.stderr.splitlines() == [
        f"pcmapq: warning: {tmp_path / 'a.yaml'}: names image 'b.png', not a.png; a.png read "
        "with this YAML's resolution, origin and thresholds (give the YAML itself to read the "
        "image it names)"]
    assert json.loads(got.stdout)["coverage"] == pytest.approx(1.0)  # a.png's walls, read
