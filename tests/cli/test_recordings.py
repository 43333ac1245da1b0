"""ROS recordings on the command line: a map read from a recording scores as the image it was
made from, a broken recording is one line and exit 2, ``pcmapq info`` lists its topics, and
``pcmapq track`` finds when the shipped recording's published maps start to drift."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from pcmapq.io import load_map
from pcmapq.results.figures import figures
from pcmapq.testing.command import run
from pcmapq.testing.paths import SAMPLE
from pcmapq.testing.recordings import Scan, write_recording


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


def test_track_refuses_scan_options_for_a_recording_of_maps(tmp_path):
    got = run("track", str(SAMPLE / "run"), str(SAMPLE / "truth.png"), "--out",
              str(tmp_path / "out"), "--every", "5")
    assert got.returncode == 2
    assert "--every apply to a run's scans" in got.stderr


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
