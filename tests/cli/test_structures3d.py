"""``pcmapq eval`` of two 3D clouds scores their 3D structures beside the 2D detectors: the
synthetic building against itself, against a map of it with a wall and a floor moved and
against one with its furniture moved and added, with the known answers
(:mod:`testkit.building3d_answers`); the block the same from run to run;
``--no-structures`` leaves it out."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pcmapq.io.writers import write_cloud
from testkit import building3d as b
from testkit.building3d_answers import Answer, answers, unmatched
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


#: The moved map's changed lines: the raised floor's feet of room A's walls and box, and the
#: moved wall's four edges, by the faces they lie on.
MOVED_LINES = {*(f"A.floor+A.wall.{side}" for side in ("x0", "x1", "y0", "y1")),
               *(f"A.box.{side}+A.floor" for side in ("x0", "x1", "y0", "y1")),
               *(f"{face}+B.wall.x1" for face in ("B.ceiling", "B.floor")),
               *(f"B.wall.x1+B.wall.{side}" for side in ("y0", "y1"))}
#: The furnished map's: the lines on room A's box's x faces, its feet and top edges (its
#: corners, 1 m high, are shorter than the lines counted).
FURNISHED_LINES = {*(f"A.box.{x}+A.floor" for x in ("x0", "x1")),
                   *(f"A.box.top+A.box.{x}" for x in ("x0", "x1"))}


def wrong(found: list[Answer]) -> list[Answer]:
    return [a for a in found if not a.right]


def test_the_moved_wall_and_floor_are_exactly_the_structures_displaced(clouds, tmp_path):
    """Room B's far wall 0.3 m further along its normal (+x) and room A's floor 0.05 m
    higher (+z): after the 3D registration and the planes' own fit, those two planes and
    their lines are reported with those displacements (within 5 mm, the wall's +0.3 along
    the truth plane's +x normal) and every other structure within 1 cm and 0.5 deg of still;
    every structure matched. (The registration alone, pulled by the two changes, reports the
    floor 0.027 m higher and room A's ceiling 0.02 m lower.)"""
    truth, _, moved = clouds
    doc, text = evaluated(moved, truth, tmp_path / "m.json")
    block = doc["structures_3d"]
    for name in ("planes", "plane_lines"):
        assert block[name]["quality"] == block[name]["precision"] == 1.0
    planes, lines = answers(block, "planes", b.MOVED), answers(block, "plane_lines", b.MOVED)
    assert {a.name: a.injected for a in planes if a.changed} == b.MOVED
    assert {a.name for a in lines if a.changed} == MOVED_LINES
    assert wrong(planes) == wrong(lines) == []
    fit = block["fit"]
    assert fit["applied"] and fit["planes_held"] == 16 and fit["planes_matched"] == 18
    assert "after the planes' own fit of" in " ".join(text.split())


def test_furniture_moved_is_displaced_and_furniture_added_is_extra(clouds, tmp_path):
    """Room A's box 0.2 m further along +x: its two x faces and their four lines displaced
    0.2 m, its top and y faces (sliding in their planes) still; a cabinet added to room A:
    its five faces are the extra planes, its eight edges on its top and the floor the extra
    lines (its upright edges, 1 m, are shorter than a line counted)."""
    truth = clouds[0]
    write_cloud(tmp_path / "furnished.ply", b.furnished_map())
    doc, _ = evaluated(tmp_path / "furnished.ply", truth, tmp_path / "f.json")
    block = doc["structures_3d"]
    planes = answers(block, "planes", b.FURNISHED)
    lines = answers(block, "plane_lines", b.FURNISHED)
    assert {a.name: a.injected for a in planes if a.changed} == b.FURNISHED
    assert {a.name for a in lines if a.changed} == FURNISHED_LINES
    assert wrong(planes) == wrong(lines) == []
    parts = b.faces(a_box_shift=0.2, cabinet=True)
    for name, count in (("planes", 5), ("plane_lines", 8)):
        missing, extra = unmatched(block, name, parts)
        assert missing == [] and len(extra) == count
        assert all(e.startswith("A.cabinet.") for e in extra), extra
        assert block[name]["precision"] == pytest.approx(
            block[name]["matched"] / (block[name]["matched"] + count))


def test_no_structures_leaves_the_block_out(clouds, tmp_path):
    truth, copy, _ = clouds
    doc, _ = evaluated(copy, truth, tmp_path / "n.json", "--no-structures")
    assert "structures_3d" not in doc
    assert doc["settings"]["structures"]["enabled"] is False
