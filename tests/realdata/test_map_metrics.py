"""map-metrics' own figures on its data (../shared/data/map-metrics): the library's no-reference
3D metrics and `pcmapq inspect` reproduce them."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.mapping.poses import read_pose_matrix, read_poses
from pcmapq.mapping.reference import posed_map
from pcmapq.metrics import noref, posed
from testkit.paths import shared

#: map-metrics' own figures on its depth test data (radius 0.2 m, more than 5 neighbours),
#: from running its code (Python 0.0.4, and its C++ rewrite's test_depth.cpp for MME and MPV).
DEPTH_MME = -3.6144387057257523
DEPTH_MPV = 0.0025390347963358565
DEPTH_MOM = 0.006183082336713371


def test_depth_data_reproduces_map_metrics():
    depth = shared("map-metrics", "depth")
    points = posed_map(depth / "pcs", read_poses(depth / "poses"))
    assert len(points) == 103_975
    got = noref.scores(points, noref.DEPTH_RADIUS, noref.MIN_KNN)
    assert got.mme == pytest.approx(DEPTH_MME, abs=1e-9)
    assert got.mpv == pytest.approx(DEPTH_MPV, abs=1e-12)
    # the 0.003242 of map-metrics' test file belongs to its earlier 473-scan data set
    assert abs(got.mpv - 0.003242216) > 5e-4
    poses = read_poses(depth / "poses")
    planes = posed.place_subset(posed.read_orthogonal_subset(depth / "orth_subset/orth-0091.npy"),
                                read_pose_matrix(depth / "poses/pose-0091.txt"), poses[0])
    assert noref.mom(points, planes, noref.DEPTH_RADIUS) == pytest.approx(DEPTH_MOM, abs=1e-12)


def _inspect(*args: str) -> tuple[int, str, str]:
    got = CliRunner().invoke(app, ["inspect", *args])
    return got.exit_code, got.stdout, got.stderr


def test_depth_scans_at_their_poses_give_map_metrics_figures():
    """map-metrics' own test data through the command line: its published MME, MPV and MOM."""
    depth = shared("map-metrics", "depth")
    code, stdout, stderr = _inspect(
        "--scans", str(depth / "pcs"), "--poses", str(depth / "poses"), "--noref-radius", "0.2",
        "--orth-subset", str(depth / "orth_subset" / "orth-0091.npy"),
        "--orth-pose", str(depth / "poses" / "pose-0091.txt"), "--json", "-")
    assert code == 0, stderr
    got = json.loads(stdout)["cloud"]
    assert got["points"] == 103_975
    assert got["mme"] == pytest.approx(-3.614439, abs=1e-6)
    assert got["mpv"] == pytest.approx(0.002539, abs=1e-6)
    assert got["mom"] == pytest.approx(0.006183, abs=1e-6)
