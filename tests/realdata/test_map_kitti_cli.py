"""`pcmapq map` and `pcmapq eval --scans` on the first KITTI scans."""

from __future__ import annotations

import json

import numpy as np

from pcmapq.mapping import read_kitti_poses, read_tum_poses
from testkit.command import run
from testkit.paths import SAMPLE, shared

TR = ("4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
      "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
      "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01")


def test_map_with_kiss_and_with_reference_poses(tmp_path):
    scans = shared("kitti00", "velodyne")
    proc = run("map", str(scans), "--out", str(tmp_path / "kiss.ply"), "--max-scans", "5",
               "--poses-out", str(tmp_path / "kiss.txt"), "--tum-out", str(tmp_path / "kiss.tum"))
    assert proc.returncode == 0, proc.stderr
    assert "mapping scans 000000.bin to 000004.bin (the first 5 of 20)" in proc.stderr
    kitti = read_kitti_poses(tmp_path / "kiss.txt")
    _, tum = read_tum_poses(tmp_path / "kiss.tum")
    assert kitti.shape == (5, 4, 4)
    np.testing.assert_allclose(kitti, tum, atol=1e-9)
    np.testing.assert_allclose(kitti[0], np.eye(4), atol=1e-12)
    # the car drives forwards (+x of the LiDAR) about 0.7-0.9 m per scan
    assert 2.0 < kitti[-1, 0, 3] < 4.5
    (tmp_path / "Tr.txt").write_text(TR + "\n")
    proc = run("map", str(scans), "--poses", str(shared("kitti00", "poses.txt")),
               "--calib", str(tmp_path / "Tr.txt"), "--out", str(tmp_path / "ref.ply"),
               "--max-scans", "5")
    assert proc.returncode == 0, proc.stderr
    proc = run("eval", str(tmp_path / "kiss.ply"), str(tmp_path / "ref.ply"), "--json", "-",
               "--force", "--voxel-3d", "0.5")  # an outdoor map: a coarser 3D voxel
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert doc["alignment"]["method"] == "3d"
    assert doc["alignment_3d"]["fitness"] >= 0.9
    assert doc["distances_3d"]["accuracy_m"]["mean"] < 0.3


def test_eval_scans_against_a_truth(tmp_path):
    """--scans builds the map in memory; TRUTH is the only positional argument."""
    scans = shared("kitti00", "velodyne")
    proc = run("eval", "--scans", str(scans), "--max-scans", "3", str(SAMPLE / "truth.png"),
               "--force", "--json", "-")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert doc["map"]["kind"] == "scans" and doc["map"]["path"] == str(scans)
    wrong = run("eval", "--scans", str(scans), str(SAMPLE / "truth.png"), str(SAMPLE / "x.png"))
    assert wrong.returncode == 2
