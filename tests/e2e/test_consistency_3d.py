"""Two 3D clouds of a street whose map sank by 0.3 m beyond x = 10, through ``pcmapq eval``:
the 3D consistency map in the JSON, its CSV, its figures and gates, its terminal line, its
pictures, and a result read back; a 2D result has none of it. A map of a run along the street
built by ``pcmapq map``, its last scans placed too low: its regions are stretches of the run."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest

from pcmapq.io.export import DISTANCE_FIELD
from pcmapq.io.writers import write_cloud
from pcmapq.results.result import Result
from testkit.command import run
from testkit.files import read_cloud
from testkit.paths import SAMPLE
from testkit.street import street, street_run, sunk

#: The street runs from x = -30 to 20 m: most of it in place, so that the 3D registration
#: fits that part, and the last 10 m sunk.
SINK_X, DEPTH = 10.0, 0.3


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory) -> tuple[Path, object]:
    """The sunk street evaluated once with every output: its folder and the run."""
    tmp = tmp_path_factory.mktemp("street")
    truth = street(-30.0, 20.0, seed=0)
    scan = street(-30.0, 20.0, seed=0)
    scan += np.random.default_rng(7).normal(0.0, 0.005, scan.shape)
    write_cloud(tmp / "truth.ply", truth)
    write_cloud(tmp / "map.ply", sunk(scan, SINK_X, DEPTH))
    proc = run("eval", str(tmp / "map.ply"), str(tmp / "truth.ply"), "--tile-3d", "10",
               "--no-noref", "--detectors", "harris", "--json", str(tmp / "r.json"),
               "--regions-3d", str(tmp / "r3.csv"), "--plot", str(tmp / "p.png"),
               "--report", str(tmp / "r.html"), "--distances", str(tmp / "d.ply"))
    assert proc.returncode == 0, proc.stderr
    return tmp, proc


def test_the_sunk_regions_and_only_they_lie_low(evaluated):
    """Regions beyond 10 m: dz -0.3 within 5 cm; the others within 5 cm of 0; the largest |dz|
    beyond 10 m; the tile as given, saved in the settings."""
    tmp, _ = evaluated
    doc = json.loads((tmp / "r.json").read_text())
    block = doc["consistency_3d"]
    assert block["tile_m"] == 10.0 and doc["settings"]["map_3d"]["tile"] == 10.0
    regions = block["regions"]
    far = [r for r in regions if r["x_m"] > SINK_X]
    near = [r for r in regions if r["x_m"] <= SINK_X]
    assert len(far) == 2 and len(near) == 8 and all(r["held"] for r in regions)
    assert all(abs(r["dz_m"] + DEPTH) < 0.05 for r in far)
    assert all(abs(r["dz_m"]) < 0.05 for r in near)
    assert block["largest_dz_at_m"][0] > SINK_X
    assert block["largest_dz_m"] == pytest.approx(DEPTH, abs=0.05)
    keys = list(doc)  # after the 3D distances and MapEval's figures
    assert keys.index("consistency_3d") == keys.index("map_3d") + 1 \
        == keys.index("distances_3d") + 2


def test_csv_figures_gates_and_terminal(evaluated):
    """The CSV holds the JSON's regions; the figures and a gate read the largest |dz|; the
    terminal names it."""
    tmp, proc = evaluated
    doc = json.loads((tmp / "r.json").read_text())
    with (tmp / "r3.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [float(r["dz_m"]) for r in rows] == pytest.approx(
        [r["dz_m"] for r in doc["consistency_3d"]["regions"]], abs=1e-6)
    assert list(rows[0])[:6] == ["x_m", "y_m", "z_m", "dx_m", "dy_m", "dz_m"]
    back = Result.from_json(tmp / "r.json")
    figures = back.figures()
    assert figures["consistency_3d.largest_dz_m"] == doc["consistency_3d"]["largest_dz_m"]
    assert figures["consistency_3d.largest_offset_m"] == pytest.approx(DEPTH, abs=0.05)
    assert back.to_dict()["consistency_3d"] == doc["consistency_3d"]
    assert "3D regions" in proc.stdout and "(too low)" in proc.stdout
    gate = run("eval", str(tmp / "map.ply"), str(tmp / "truth.ply"), "--tile-3d", "10",
               "--no-noref", "--detectors", "harris", "--fail-over",
               "consistency_3d.largest_dz_m=0.1", "-q")
    assert gate.returncode == 3 and "consistency_3d.largest_dz_m" in gate.stderr


def test_pictures_and_distance_colours(evaluated):
    """The plot and the report hold the 3D pictures; the distance cloud carries an RGB colour
    of each distance for viewers that show no scalar field (viridis: dark for 0, yellow for
    the largest --tau and beyond)."""
    tmp, _ = evaluated
    assert (tmp / "p.png").read_bytes()[:4] == b"\x89PNG"
    page = (tmp / "r.html").read_text()
    assert "Where the map bends in 3D" in page
    assert re.search(r"largest dz -0\.(2[5-9]|3[0-5])\d m \(too low\)", page)
    from matplotlib import colormaps

    cloud = read_cloud(tmp / "d.ply")
    colours, distance = cloud["colors"].astype(int), cloud[DISTANCE_FIELD].ravel()
    assert colours.shape == (len(distance), 3)
    # the sunk part lies 0.3 m off, the rest on the truth: both read in their colour
    assert (distance > 0.25).any() and (distance < 0.02).any()
    want = np.round(colormaps["viridis"](np.clip(distance / 0.5, 0, 1))[:, :3] * 255)
    assert np.abs(colours - want).max() <= 1


def test_a_2d_result_has_no_3d_consistency(tmp_path):
    """The shipped sample (a 2D cloud against an image): no consistency_3d block, no map_3d
    settings; --regions-3d writes the header alone and says why."""
    proc = run("eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"), "--json",
               str(tmp_path / "r.json"), "--regions-3d", str(tmp_path / "r3.csv"),
               "--no-noref", "--detectors", "harris")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "r.json").read_text())
    assert "consistency_3d" not in doc and "map_3d" not in doc["settings"]
    assert (tmp_path / "r3.csv").read_text().count("\n") == 1
    assert "pcmapq: warning:" in proc.stderr and "needs two 3D clouds" in proc.stderr


@pytest.fixture(scope="module")
def run_mapped(tmp_path_factory) -> Path:
    """A car's 30 scans of the street from x = -29 m (a scan every 2 m), its poses from the
    24th on (x = 19 m) 0.3 m too low, mapped by ``pcmapq map --poses``; the truth the street
    itself."""
    tmp = tmp_path_factory.mktemp("run")
    truth = street(-30.0, 30.0, spacing=0.15, seed=0)
    seen, poses = street_run(truth + np.random.default_rng(7).normal(0.0, 0.005, truth.shape),
                             30, step=2.0, start=-29.0)
    (tmp / "scans").mkdir()
    for index, points in enumerate(seen):
        np.save(tmp / "scans" / f"{index:03d}.npy", points)
    poses[24:, 2, 3] -= DEPTH
    np.savetxt(tmp / "poses.txt", poses[:, :3, :].reshape(len(poses), 12))
    write_cloud(tmp / "truth.ply", truth)
    proc = run("map", str(tmp / "scans"), "--poses", str(tmp / "poses.txt"), "--out",
               str(tmp / "map.ply"), "-q")
    assert proc.returncode == 0, proc.stderr
    return tmp


def test_a_map_built_from_scans_is_cut_into_stretches_of_its_run(run_mapped):
    """``pcmapq map`` writes each point's scan; ``pcmapq eval`` cuts such a map into stretches
    of 4 scans: those of scans 24 on lie 0.3 m low, the others in place, every whole one
    held; the JSON, the CSV and the terminal name the scans, and the map in the truth's frame
    (``--aligned``) keeps them; ``--stretch-3d 0`` cuts it into tiles."""
    tmp = run_mapped
    scan = read_cloud(tmp / "map.ply")["scan"]  # a voxel's mean scan
    assert scan.min() >= 0 and 28 <= scan.max() <= 29
    proc = run("eval", str(tmp / "map.ply"), str(tmp / "truth.ply"), "--no-noref",
               "--detectors", "harris", "--json", str(tmp / "r.json"), "--regions-3d",
               str(tmp / "r3.csv"), "--aligned", str(tmp / "a.ply"))
    assert proc.returncode == 0, proc.stderr
    block = json.loads((tmp / "r.json").read_text())["consistency_3d"]
    assert block["tile_m"] is None and block["stretch_scans"] == 4
    regions = block["regions"]
    assert [(r["first_scan"], r["last_scan"]) for r in regions] == \
        [(k, min(k + 3, 29)) for k in range(0, 30, 4)]
    assert all(r["held"] for r in regions[:-1])
    assert all(abs(r["dz_m"] + DEPTH) < 0.05 for r in regions if r["first_scan"] >= 24)
    assert all(abs(r["dz_m"]) < 0.05 for r in regions if r["last_scan"] < 24)
    with (tmp / "r3.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [int(r["first_scan"]) for r in rows] == [r["first_scan"] for r in regions]
    assert re.search(r"largest dz -0\.[23]\d\d m \(too low\) at .*scans 2[48]-", proc.stdout)
    assert Result.from_json(tmp / "r.json").to_dict()["consistency_3d"] == block
    # the map in the truth's frame keeps each point's scan
    np.testing.assert_array_equal(read_cloud(tmp / "a.ply")["scan"], scan)
    tiles = run("eval", str(tmp / "map.ply"), str(tmp / "truth.ply"), "--no-noref",
                "--detectors", "harris", "--stretch-3d", "0", "--json", "-", "-q")
    assert tiles.returncode == 0, tiles.stderr
    block = json.loads(tiles.stdout)["consistency_3d"]
    assert block["tile_m"] == 8.0 and "stretch_scans" not in block


def test_a_stretch_that_cuts_the_run_too_finely_is_refused_first(run_mapped):
    """A map whose scans another program numbered by the ten thousand, and a stretch of 4 scans:
    refused in one line naming the map and the way out, before any work (exit 2)."""
    tmp = run_mapped
    cloud = read_cloud(tmp / "map.ply")
    write_cloud(tmp / "wide.ply", cloud["positions"], scan=cloud["scan"].ravel() * 1e4)
    proc = run("eval", str(tmp / "wide.ply"), str(tmp / "truth.ply"), "--stretch-3d", "4")
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().count("\n") == 0
    assert re.search(r"wide\.ply: --stretch-3d 4: the map's scans run from \d+ to \d+: "
                     r"\d+ stretches of 4, more than 10000; give a larger stretch, or 0 for "
                     r"tiles", proc.stderr)
