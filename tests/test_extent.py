"""Inputs whose extent looks wrong (a copy or an outlier far away, millimetres, a resolution not in
metres, one straight wall) are refused with a line that says what looks wrong and how to fix it;
``--map-crop`` / ``--truth-crop`` keep the part that matters and then score as the clean input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import open3d as o3d
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.evaluation.inputs import check_structure
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.io.extent import MAX_SPAN, check_span, crop, hint, main_group
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN
from pcmapq.settings.table import OptionError, parse_box

SAMPLE = Path(__file__).resolve().parents[1] / "data" / "sample"


@pytest.fixture(scope="module")
def scan_points() -> np.ndarray:
    return np.asarray(o3d.io.read_point_cloud(str(SAMPLE / "scan.ply")).points)


def _box(points: np.ndarray) -> np.ndarray:
    return np.array([*points[:, :2].min(axis=0), *points[:, :2].max(axis=0)])


def test_main_group_boxes_the_points_near_each_other():
    rng = np.random.default_rng(1)
    room = rng.uniform([0, 0], [30, 20], (5000, 2))
    copy = room + [20_000.0, 0.0]
    box = main_group(np.vstack([room, room, copy]))
    assert box is not None
    lo, hi = [-1.1, -1.1, 30.0, 20.0], [0.0, 0.0, 31.1, 21.1]  # the room grown by up to 1.1 m
    assert np.all((np.array(box) >= lo) & (np.array(box) <= hi)), box
    assert main_group(room) is None
    # a large map with no gap (a 400 m campus) is one group
    assert main_group(rng.uniform([0, 0], [400, 300], (20000, 2))) is None


def test_hint_says_which_points_are_far_and_the_crop_that_keeps_the_rest(scan_points):
    far = np.vstack([scan_points, [[5000.0, 3.0, 1.0]]])
    text = hint(PointMap(Path("m.npy"), far, True), "--map-crop")
    assert text.startswith(f"1 of its {len(far):,} points lies far from the others")
    box = text.split("--map-crop ")[1].split(" keeps")[0]
    lo_hi = np.array([float(v) for v in box.split(",")])
    inside = _box(scan_points)
    assert np.all(lo_hi[:2] <= inside[:2]) and np.all(lo_hi[2:] >= inside[2:])
    assert np.all(lo_hi[:2] >= inside[:2] - 1.2) and np.all(lo_hi[2:] <= inside[2:] + 1.2)


def test_hint_names_millimetres_and_resolutions_that_are_not_metres(scan_points):
    mm = PointMap(Path("mm.ply"), scan_points * 1000.0, True)
    assert "millimetres" in hint(mm, "--truth-crop")
    assert "cells are 1e-05 m wide" in hint(PointMap(Path("c.ply"), scan_points, True),
                                            "--truth-crop", cell=1e-5)
    state = np.zeros((10, 10), np.int8)
    image = OccupancyMap(Path("t.yaml"), MetricGrid(1e9, (0.0, 0.0, 0.0), (10, 10)), state)
    assert "cells are 1e+09 m wide" in hint(image, "--truth-crop")
    assert hint(PointMap(Path("s.ply"), scan_points, True), "--map-crop") == ""


def test_an_input_wider_than_the_limit_is_refused_saying_why(scan_points):
    far = PointMap(Path("m.npy"), np.vstack([scan_points, [[1e300, 0.0, 1.0]]]), True)
    with pytest.raises(InputError, match=f"m.npy: wider than {MAX_SPAN / 1000:.0f} km.*--map-crop"):
        check_span(far, "--map-crop")
    check_span(PointMap(Path("s.ply"), scan_points, True), "--map-crop")


def test_crop_of_an_image_keeps_the_cells_whose_centres_lie_in_the_box():
    grid = MetricGrid(0.1, (-1.0, -2.0, 0.0), (40, 60))
    state = np.random.default_rng(2).choice([OCCUPIED, FREE, UNKNOWN], grid.shape).astype(np.int8)
    cut = crop(OccupancyMap(Path("m.png"), grid, state), (0.0, 0.0, 2.0, 1.0), "--map-crop")
    centres = grid.cell_centres(np.ones(grid.shape, bool)).reshape(*grid.shape, 2)
    inside = ((centres[..., 0] >= 0) & (centres[..., 0] <= 2) & (centres[..., 1] >= 0)
              & (centres[..., 1] <= 1))
    assert cut.state.shape == (10, 20)
    np.testing.assert_array_equal(cut.state.ravel(), state[inside])
    kept = cut.grid.cell_centres(np.ones(cut.state.shape, bool))
    np.testing.assert_allclose(kept, centres[inside], atol=1e-9)


def test_crop_of_a_turned_image_makes_cells_outside_the_box_unknown():
    grid = MetricGrid(0.1, (0.0, 0.0, np.radians(30.0)), (50, 50))
    state = np.full(grid.shape, OCCUPIED, np.int8)
    cut = crop(OccupancyMap(Path("m.png"), grid, state), (0.0, 1.0, 2.0, 3.0), "--map-crop")
    centres = cut.grid.cell_centres(cut.state == OCCUPIED)
    assert len(centres) > 0 and (cut.state == UNKNOWN).any()
    assert np.all((centres >= [0.0, 1.0]) & (centres <= [2.0, 3.0]))


def test_crop_of_a_cloud_and_a_crop_that_keeps_nothing(scan_points):
    cloud = PointMap(Path("s.ply"), scan_points, True)
    cut = crop(cloud, (0.0, 0.0, 5.0, 5.0), "--map-crop")
    xy = scan_points[:, :2]
    assert len(cut.points) == int(np.all((xy >= 0) & (xy <= 5), axis=1).sum())
    with pytest.raises(InputError, match="s.ply: --map-crop 100.0,100.0,101.0,101.0 keeps none"):
        crop(cloud, (100.0, 100.0, 101.0, 101.0), "--map-crop")


def test_one_straight_wall_has_nothing_to_align_and_an_l_has():
    x = np.linspace(0.0, 10.0, 2000)
    wall = np.column_stack([x, 0.02 * np.sin(x)])
    with pytest.raises(EvaluationError, match="one straight line .10.0 m long"):
        check_structure(Path("line.npy"), wall)
    corner = np.vstack([wall, np.column_stack([np.zeros(500), np.linspace(0, 3, 500)])])
    check_structure(Path("corner.npy"), corner)


@pytest.mark.parametrize("text", ["0,0,1", "0,0,1,x", "1,0,0,1", "0,0,1,nan", "0,1,1,1"])
def test_a_bad_box_is_a_usage_error(text):
    with pytest.raises(OptionError, match="expected a box x0,y0,x1,y1") as err:
        parse_box(text, "--map-crop")
    assert err.value.option == "--map-crop"


def _eval(*args: str) -> tuple[int, str, str]:
    got = CliRunner().invoke(app, ["eval", *args])
    return got.exit_code, got.stdout, got.stderr


def _crop_option(stderr: str, option: str) -> str:
    return stderr.split(f"{option} ")[-1].split(" keeps")[0]


@pytest.mark.e2e  # whole evaluations
def test_a_truth_with_a_copy_far_away_is_refused_then_cropped_to_the_clean_result(
        tmp_path, scan_points):
    """The sample's scan as truth, plus its copy 20 km away: refused (exit 2) with the box of the
    near copy; with that --truth-crop it scores exactly as the clean truth."""
    clean, doubled = tmp_path / "clean.npy", tmp_path / "doubled.npy"
    np.save(clean, scan_points)
    np.save(doubled, np.vstack([scan_points, scan_points + [20_000.0, 0.0, 0.0]]))
    code, _, stderr = _eval(str(SAMPLE / "truth.png"), str(doubled), "--max-memory", "4")
    assert code == 2 and len(stderr.strip().splitlines()) == 1, stderr
    assert f"{len(scan_points):,} of its {2 * len(scan_points):,} points lie far" in stderr
    box = _crop_option(stderr, "--truth-crop")
    runs = []
    for truth, extra in ((clean, []), (doubled, ["--truth-crop", box])):
        out = tmp_path / f"{truth.stem}.json"
        code, _, stderr = _eval(str(SAMPLE / "truth.png"), str(truth), "--quiet", "--json",
                                str(out), *extra)
        assert code == 0, stderr
        runs.append(json.loads(out.read_text()))
    clean_run, cropped_run = runs
    for name in ("harris", "hough", "sift"):
        assert cropped_run["detectors"][name] == clean_run["detectors"][name]
    assert cropped_run["settings"]["truth"]["crop"] == [float(v) for v in box.split(",")]


@pytest.mark.e2e  # whole evaluations
def test_a_map_with_a_point_at_1e300_is_refused_then_cropped(tmp_path, scan_points):
    path = tmp_path / "outlier.npy"
    np.save(path, np.vstack([scan_points, [[1e300, 0.0, 1.0]]]))
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"))
    assert code == 2 and "wider than 100 km" in stderr and "1 of its" in stderr, stderr
    assert "Traceback" not in stderr and len(stderr.strip().splitlines()) == 1
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"), "--quiet", "--map-crop",
                            _crop_option(stderr, "--map-crop"))
    assert code == 0, stderr


def test_a_map_in_millimetres_with_scale_auto_says_so(tmp_path, scan_points):
    path = tmp_path / "mm.npy"
    np.save(path, scan_points * 1000.0)
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"), "--scale", "auto")
    assert code == 1 and "lowest scale --scale auto tries (0.2)" in stderr, stderr
    assert "millimetres" in stderr and len(stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("mistake", ["millimetres", "cells of 50 m"])
def test_a_unit_mistake_on_the_map_side_is_refused_before_the_search(mistake, tmp_path,
                                                                      scan_points, monkeypatch):
    """The truth's mistakes, made on the map's side (a cloud in millimetres, a YAML whose
    resolution is 50): exit 1 with the same reason the truth's side gives, before the global
    search, which took 30-40 s and 8 GB on them."""
    if mistake == "millimetres":
        path = tmp_path / "mm.npy"
        np.save(path, scan_points * 1000.0)
        why = "millimetres"
    else:
        (tmp_path / "t.png").write_bytes((SAMPLE / "truth.png").read_bytes())
        text = (SAMPLE / "truth.yaml").read_text()
        path = tmp_path / "t.yaml"
        path.write_text("\n".join("resolution: 50" if line.startswith("resolution") else
                                  "image: t.png" if line.startswith("image") else line
                                  for line in text.splitlines()))
        why = "its cells are 50 m wide"
    called = []
    import pcmapq.align.planar as planar

    original = planar.coarse_search
    monkeypatch.setattr(planar, "coarse_search",
                        lambda *a, **k: called.append(1) or original(*a, **k))
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"))
    assert code == 1 and why in stderr and str(path) in stderr, stderr
    assert len(stderr.strip().splitlines()) == 1 and not called


def test_a_map_of_one_straight_wall_is_refused_with_exit_1(tmp_path):
    path = tmp_path / "line.npy"
    np.save(path, np.column_stack([np.linspace(0, 10, 2000), np.zeros(2000)]))
    code, _, stderr = _eval(str(path), str(SAMPLE / "truth.yaml"))
    assert code == 1 and "one straight line" in stderr and str(path) in stderr, stderr


def test_max_memory_reaches_the_loaders(tmp_path):
    """A limit below what the truth image needs stops at its header (the loader), naming it."""
    code, _, stderr = _eval(str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.yaml"),
                            "--max-memory", "0.1")
    assert code == 2 and "truth.png (521 x 361 pixels declared in its header)" in stderr, stderr


@pytest.mark.parametrize("name", ["b.ply", "a.ply", "b.pcd", "a.pcd", "c.npy", "k.bin"])
def test_every_cloud_loader_checks_the_points_declared_against_the_limit(tmp_path, name):
    """A limit that holds half of what the declared points need refuses the file before it is
    read; one that holds them all loads it."""
    from pcmapq.core import memory

    n = 20_000
    points = np.random.default_rng(3).uniform(0, 5, (n, 3))
    path = tmp_path / name
    if name.endswith(".npy"):
        np.save(path, points)
    elif name.endswith(".bin"):
        np.column_stack([points, np.zeros(n)]).astype("<f4").tofile(path)
    else:
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
        assert o3d.io.write_point_cloud(str(path), cloud, write_ascii=name.startswith("a"))
    need = memory.needed_bytes(0, 0, 0.0, n)
    with pytest.raises(InputError, match=f"{name}.*needs about"):
        load_map(path, memory_limit=need - 50 * n)
    assert len(load_map(path, memory_limit=need).points) == n


def test_inspect_refuses_a_yaml_of_50_m_cells_in_one_line(tmp_path):
    """`pcmapq inspect` goes through eval's input checks: the sample's YAML with resolution 50
    (a 26 km image whose walls' image would take terabytes) is refused from its size, with
    the reason, in one line; it ended in an OpenCV traceback."""
    (tmp_path / "t.png").write_bytes((SAMPLE / "truth.png").read_bytes())
    path = tmp_path / "t.yaml"
    path.write_text("\n".join("resolution: 50" if line.startswith("resolution") else
                              "image: t.png" if line.startswith("image") else line
                              for line in (SAMPLE / "truth.yaml").read_text().splitlines()))
    got = CliRunner().invoke(app, ["inspect", str(path)])
    assert got.exit_code == 2 and "its cells are 50 m wide" in got.stderr, got.stderr
    assert len(got.stderr.strip().splitlines()) == 1 and str(path) in got.stderr
