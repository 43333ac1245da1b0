"""ROS recordings on the command line: a map read from a recording scores as the image it was
made from, a broken recording is one line and exit 2, ``pcmapq info`` lists its topics, and
``pcmapq track`` finds when the shipped recording's published maps start to drift."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from pcmapq.core.cells import UNKNOWN
from pcmapq.io import load_map
from pcmapq.results.figures import figures
from testkit.command import run
from testkit.paths import SAMPLE
from testkit.recordings import Scan, write_recording


@pytest.fixture(scope="module")
def truth():
    return load_map(SAMPLE / "truth.yaml")


def test_a_map_from_a_recording_scores_as_its_image(truth, tmp_path):
    path = write_recording(tmp_path / "run", [(1.0, truth.state, truth.grid)], "ros2-sqlite")
    docs = []
    for map_path in (path, SAMPLE / "truth.yaml"):
        got = run("eval", str(map_path), str(SAMPLE / "truth.png"), "--no-noref", "--json", "-")
        assert got.returncode == 0, got.stderr
        docs.append(figures(json.loads(got.stdout)))
    bag, image = docs
    assert bag.keys() == image.keys()
    for key, value in bag.items():
        if isinstance(value, float):
            assert value == pytest.approx(image[key], abs=1e-9), key
        else:
            assert value == image[key], key


@pytest.mark.parametrize("damage", ["truncated", "empty", "garbage"])
def test_a_broken_recording_is_one_line_and_exit_2(damage, truth, tmp_path):
    good = write_recording(tmp_path / "good.mcap", [(1.0, truth.state, truth.grid)], "mcap")
    bad = tmp_path / "bad.mcap"
    data = good.read_bytes()
    bad.write_bytes({"truncated": data[:len(data) // 2], "empty": b"",
                     "garbage": b"\x89MCAP0\r\n" + bytes(range(256)) * 4}[damage])
    for args in (("info", str(bad)), ("eval", str(bad), str(SAMPLE / "truth.png"))):
        got = run(*args)
        assert got.returncode == 2, got.stderr
        line, = got.stderr.strip().splitlines()
        assert line.startswith(f"pcmapq: error: {bad}: ")


def test_info_lists_topics_counts_and_span(truth, tmp_path):
    path = write_recording(tmp_path / "run.bag", [(1.0, truth.state, truth.grid),
                                                 (4.5, truth.state, truth.grid)], "ros1",
                           scans=[Scan(2.0, np.ones(5), 0.0, 0.1)])
    got = run("info", str(path), "--json", "-")
    assert got.returncode == 0, got.stderr
    record = json.loads(got.stdout)
    assert record["kind"] == "recording" and record["duration_s"] == pytest.approx(3.5)
    assert record["topics"] == [
        {"name": "/map", "type": "nav_msgs/msg/OccupancyGrid", "count": 2},
        {"name": "/scan", "type": "sensor_msgs/msg/LaserScan", "count": 1}]


def test_track_finds_when_the_shipped_recordings_maps_start_to_drift(tmp_path):
    """data/sample/run: the plan published as it is explored, one map every 10 s, in a frame of
    its own, drifting north from 30 s on (tools/make_sample.py). Every map is scored on the
    recording's time axis; the worst drop starts at 30 s."""
    got = run("track", str(SAMPLE / "run"), str(SAMPLE / "truth.png"), "--out",
              str(tmp_path / "out"), "--json", "-")
    assert got.returncode == 0, got.stderr
    doc = json.loads(got.stdout)
    rows = list(csv.DictReader((tmp_path / "out" / "track.csv").open()))
    assert [float(r["time_s"]) for r in rows] == [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0]
    assert all(r["distance_m"] == "" and r["scored"] == "1" for r in rows)
    start = doc["worst_drop"]["start"]
    assert float(rows[start]["time_s"]) == 30.0
    precision = [float(r["precision"]) for r in rows]
    assert min(precision[:3]) > 0.9 > max(precision[3:])
    html = (tmp_path / "out" / "track.html").read_text()
    assert "7 maps published" in html and "published at 30.0 s" in html


def test_a_recordings_maps_thinned_by_every_s_keep_the_last(tmp_path):
    got = run("track", str(SAMPLE / "run"), str(SAMPLE / "truth.png"), "--out",
              str(tmp_path / "out"), "--every-s", "25", "--json", "-")
    assert got.returncode == 0, got.stderr
    rows = list(csv.DictReader((tmp_path / "out" / "track.csv").open()))
    assert [float(r["time_s"]) for r in rows] == [0.0, 30.0, 60.0]


def test_track_takes_a_scan_option_as_a_choice_of_the_scans(tmp_path):
    """A scan option (--every) reads the recording's scans: this one has none; options of
    both kinds are refused."""
    out = str(tmp_path / "out")
    got = run("track", str(SAMPLE / "run"), str(SAMPLE / "truth.png"), "--out", out,
              "--every", "5")
    assert got.returncode == 2
    assert got.stderr == (f"pcmapq: error: {SAMPLE / 'run'}: no sensor_msgs/PointCloud2 or "
                          "sensor_msgs/LaserScan topic; topics: /map "
                          "(nav_msgs/msg/OccupancyGrid, 7)\n")
    got = run("track", str(SAMPLE / "run"), str(SAMPLE / "truth.png"), "--out", out,
              "--every", "5", "--every-s", "10")
    assert got.returncode == 2
    assert got.stderr == (f"pcmapq: error: {SAMPLE / 'run'}: --every-s score a recording's "
                          "published maps, --every a run's scans: give the options of one\n")


def test_a_map_at_a_time_is_the_one_published_then(truth, tmp_path):
    got = run("eval", str(SAMPLE / "run"), str(SAMPLE / "truth.png"), "--at", "15",
              "--no-noref", "--json", "-")
    assert got.returncode == 0, got.stderr
    doc = json.loads(got.stdout)
    assert doc["settings"]["map"]["at"] == 15.0 and "--at 15.0" in doc["pcmapq"]["command"]
    assert doc["alignment"]["verdict"] == "same place"
    assert doc["detectors"]["harris"]["precision"] > 0.85  # the map of 10 s: before the drift


def test_survey_outputs_hold_what_the_ply_outputs_hold(tmp_path):
    """--distances as .laz holds the PLY's points and distances (extra dimension distance_m);
    --aligned as .las the PLY's points."""
    import laspy
    import open3d as o3d

    for distances, aligned in (("d.ply", "a.ply"), ("d.laz", "a.las")):
        got = run("eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"), "-q",
                  "--no-noref", "--distances", str(tmp_path / distances),
                  "--aligned", str(tmp_path / aligned))
        assert got.returncode == 0, got.stderr
    ply = o3d.t.io.read_point_cloud(str(tmp_path / "d.ply"))
    las = laspy.read(tmp_path / "d.laz")
    xyz = ply.point["positions"].numpy()
    assert len(las.points) == len(xyz)
    assert np.abs(np.column_stack([las.x, las.y, las.z]) - xyz).max() < 0.0006
    assert np.array_equal(np.asarray(las["distance_m"]),
                          ply.point["scalar_distance_m"].numpy().ravel())
    a_ply, a_las = load_map(tmp_path / "a.ply").points, load_map(tmp_path / "a.las").points
    assert a_ply.shape == a_las.shape and np.abs(a_ply - a_las).max() < 0.0006


@pytest.mark.parametrize(("name", "data"), [("short.las", b"LASF" + bytes(50)),
                                            ("empty.laz", b""),
                                            ("bad.e57", b"ASTM-E57" + bytes(60))])
def test_a_broken_survey_file_is_one_line_and_exit_2(name, data, tmp_path):
    path = tmp_path / name
    path.write_bytes(data)
    got = run("info", str(path))
    assert got.returncode == 2
    line, = got.stderr.strip().splitlines()
    assert line.startswith(f"pcmapq: error: {path}: ")


def test_track_and_eval_at_share_the_recordings_time_axis(truth, tmp_path):
    """Maps recorded at 1, 11 and 21 s of the bag's clock: track's steps are at 0, 10 and 20 s
    from its start, and eval --at takes seconds from its start too, its JSON naming the
    message scored (topic, index, time from the start, header stamp)."""
    second, third = truth.state.copy(), truth.state.copy()
    second[:40], third[:80] = UNKNOWN, UNKNOWN
    path = write_recording(tmp_path / "run.mcap", [(1.0, truth.state, truth.grid),
                                                  (11.0, second, truth.grid),
                                                  (21.0, third, truth.grid)], "mcap")
    got = run("track", str(path), str(SAMPLE / "truth.png"), "--out", str(tmp_path / "out"),
              "-q")
    assert got.returncode == 0, got.stderr
    rows = list(csv.DictReader((tmp_path / "out" / "track.csv").open()))
    assert [float(r["time_s"]) for r in rows] == [0.0, 10.0, 20.0]
    for at, index in (("0.5", 0), ("10.5", 1)):
        got = run("eval", str(path), str(SAMPLE / "truth.png"), "--at", at, "--no-noref",
                  "--json", "-", "-q")
        assert got.returncode == 0, got.stderr
        assert json.loads(got.stdout)["map"] == {
            "path": str(path), "kind": "OccupancyGrid", "topic": "/map", "index": index,
            "time_s": 10.0 * index, "stamp_s": 1.0 + 10.0 * index}


@pytest.mark.parametrize("layout", ["ros1", "ros2-sqlite", "mcap"])
def test_info_of_an_empty_recording_says_it_holds_no_message(layout, tmp_path):
    path = write_recording(tmp_path / {"ros1": "e.bag", "mcap": "e.mcap"}.get(layout, "e"), [],
                           layout)
    got = run("info", str(path))
    assert got.returncode == 0, got.stderr
    assert got.stdout == f"{path}: a ROS recording holding no message\n"
    record = json.loads(run("info", str(path), "--json", "-").stdout)
    assert (record["start_s"], record["end_s"], record["duration_s"]) == (None, None, 0.0)


def corridor_scans(start_s: float, period_s: float) -> tuple[list[Scan], list, np.ndarray]:
    """A robot driving 8 m east along the corridor of synth.building_plan(0), a 181-beam laser
    scan (ray-cast against the plan's walls, -90 to 90 degrees) and an odometry pose every 0.2
    m, ``period_s`` apart from ``start_s`` (seconds of the bag's clock); the plan's walls."""
    from testkit import synth

    walls = synth.building_plan(0)
    xy = np.column_stack([1.0 + 0.2 * np.arange(41), np.full(41, 7.8)])
    angles = np.radians(np.arange(-90.0, 90.5, 1.0))
    dx, dy = np.cos(angles)[None, :, None], np.sin(angles)[None, :, None]
    ex, ey = walls[:, 2] - walls[:, 0], walls[:, 3] - walls[:, 1]
    wx, wy = walls[:, 0] - xy[:, 0, None, None], walls[:, 1] - xy[:, 1, None, None]
    cross = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        along, on = (wx * ey - wy * ex) / cross, (wx * dy - wy * dx) / cross
    hit = (np.abs(cross) > 1e-12) & (along > 1e-9) & (on >= 0.0) & (on <= 1.0)
    ranges = np.where(hit, along, np.inf).min(axis=2)
    ranges[np.isinf(ranges)] = np.nan  # no return
    scans, poses = [], []
    for k, (x, y) in enumerate(xy):
        pose = np.eye(4)
        pose[:2, 3] = x, y
        scans.append(Scan(start_s + k * period_s, ranges[k], float(angles[0]), np.pi / 180))
        poses.append((start_s + k * period_s, pose))
    return scans, poses, walls


def test_track_builds_a_recordings_scans_when_asked_with_their_times(tmp_path):
    """A recording of a published map, laser scans and odometry: --scan-topic chooses the
    scans; each step's time_s is its last scan's, seconds from the recording's start (its
    map, 0.5 s before the first scan)."""
    from pcmapq.io.writers import write_ros_map
    from testkit import synth

    scans, poses, walls = corridor_scans(100.5, 0.25)
    grid = synth.plan_grid(walls, 0.05)
    image = synth.render(walls, grid)
    truth_png = write_ros_map(tmp_path / "plan.png", image, 0.05, grid.origin[:2])
    published = load_map(truth_png)
    path = write_recording(tmp_path / "run.mcap", [(100.0, published.state, published.grid)],
                           "mcap", scans=scans, poses=poses)
    got = run("track", str(path), str(truth_png), "--scan-topic", "/scan", "--pose-topic",
              "/odom", "--every", "20", "--out", str(tmp_path / "out"), "-q")
    assert got.returncode == 0, got.stderr
    rows = list(csv.DictReader((tmp_path / "out" / "track.csv").open()))
    assert [int(r["scans"]) for r in rows] == [20, 40, 41]
    assert [float(r["time_s"]) for r in rows] == [0.5 + 0.25 * 19, 0.5 + 0.25 * 39,
                                                  0.5 + 0.25 * 40]
    assert [r["scored"] for r in rows] == ["1", "1", "1"]


def test_scans_with_no_return_are_one_line_in_map_and_track(tmp_path):
    """Every beam without a return: map refuses in one line, track's steps say why (exit 1),
    neither with a traceback."""
    scans = [Scan(1.0 + 0.25 * k, np.full(181, np.nan), -np.pi / 2, np.pi / 180)
             for k in range(5)]
    poses = [(1.0 + 0.25 * k, np.eye(4)) for k in range(5)]
    path = write_recording(tmp_path / "run.mcap", [], "mcap", scans=scans, poses=poses)
    got = run("map", str(path), "--pose-topic", "/odom", "--out", str(tmp_path / "m.ply"))
    assert got.returncode == 2
    assert got.stderr == (f"pcmapq: error: {path}: the scans hold no point to map (no return "
                          "within their range limits)\n")
    got = run("track", str(path), str(SAMPLE / "truth.png"), "--pose-topic", "/odom",
              "--out", str(tmp_path / "out"), "-q")
    assert got.returncode == 1
    assert got.stderr == (f"pcmapq: error: {path}: no step could be scored; the last: {path}: "
                          "the scans so far hold no point (no return within their range "
                          "limits)\n")
