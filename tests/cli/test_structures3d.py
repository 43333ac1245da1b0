"""``pcmapq eval`` of two 3D clouds scores their 3D structures beside the 2D detectors: the
synthetic building against itself and against a map of it with a wall and a floor moved;
the block the same from run to run; ``--no-structures`` leaves it out."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pcmapq.io.writers import write_cloud
from testkit import building3d as b
from testkit.command import run


@pytest.fixture(scope="module")
def clouds(tmp_path_factory) -> tuple[Path, Path, Path]:
    """The building (truth), a copy of the same points (map) and its moved map, as .ply."""
    folder = tmp_path_factory.mktemp("building")
    truth = b.cloud(b.faces(), seed=1)
    write_cloud(folder / "truth.ply", truth)
    write_cloud(folder / "copy.ply", truth)
    write_cloud(folder / "moved.ply", b.moved_map())
    return folder / "truth.ply", folder / "copy.ply", folder / "moved.ply"


def evaluated(map_: Path, truth: Path, out: Path, *extra: str) -> tuple[dict, str]:
    got = run("eval", str(map_), str(truth), "--json", str(out), "--no-noref", *extra)
    assert got.returncode == 0, got.stderr
    return json.loads(out.read_text()), got.stdout


def test_a_cloud_against_itself_matches_every_structure(clouds, tmp_path):
    truth, copy, _ = clouds
    doc, text = evaluated(copy, truth, tmp_path / "a.json")
    for name in ("planes", "plane_lines"):
        block = doc["structures_3d"][name]
        assert (block["quality"], block["precision"], block["f1"]) == (1.0, 1.0, 1.0)
        assert block["missing"] == block["extra"] == []
    assert doc["structures_3d"]["planes"]["truth_structures"] == 18
    assert doc["settings"]["structures"]["voxel"] == 0.1
    assert any(line.split()[:4] == ["planes", "1.000", "1.000", "1.000"]
               for line in text.splitlines())
    # the same block from run to run, byte for byte
    again, _ = evaluated(copy, truth, tmp_path / "b.json")
    assert json.dumps(again["structures_3d"]) == json.dumps(doc["structures_3d"])


def test_the_moved_wall_and_floor_are_displaced_after_the_3d_registration(clouds, tmp_path):
    """The registration fits the map to the truth as a whole: the wall's 0.3 m and the
    floor's 0.05 m stay the largest displacements, every plane matched."""
    truth, _, moved = clouds
    doc, _ = evaluated(moved, truth, tmp_path / "m.json")
    planes = doc["structures_3d"]["planes"]
    assert planes["quality"] == planes["precision"] == 1.0
    sizes = sorted(abs(m["displacement_m"]) for m in planes["matches"])
    assert sizes[-1] == pytest.approx(0.3, abs=0.03)
    assert sizes[-2] < 0.06


def test_no_structures_leaves_the_block_out(clouds, tmp_path):
    truth, copy, _ = clouds
    doc, _ = evaluated(copy, truth, tmp_path / "n.json", "--no-structures")
    assert "structures_3d" not in doc
    assert doc["settings"]["structures"]["enabled"] is False
