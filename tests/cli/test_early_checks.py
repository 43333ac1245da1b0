"""Mistakes caught before any work: output paths, options that cannot work together, and
`pcmapq map`'s poses and scans. Each: exit 2 (or a warning) and one line naming the problem."""

from __future__ import annotations

import numpy as np
import pytest

from testkit.command import run
from testkit.paths import SAMPLE


def one_line(proc) -> str:
    """The one line a refused command printed on stderr."""
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, (proc.returncode, proc.stderr)
    return lines[0]


@pytest.mark.parametrize("option,name,problem", [
    ("--plot", "p.jpg", "--plot writes .png, .svg or .pdf, not '.jpg'"),
    ("--json", "r.txt", "--json writes .json, not '.txt'"),
    ("--vectors", "missing/v.csv", "folder '{tmp}/missing' does not exist"),
    ("--report", "folder.html", "--report: is a folder"),
    ("--aligned", "a.png", "--aligned writes .ply, .pcd, .las or .laz, not '.png'"),
    ("--transform", "T.npy", "--transform writes .txt, not '.npy'"),
    ("--distances", "d.pcd", "--distances writes .ply, .las or .laz, not '.pcd'"),
])
def test_bad_output_paths_stop_before_any_work(option, name, problem, tmp_path):
    """The map does not exist: the output's line comes first, so nothing was read."""
    (tmp_path / "folder.html").mkdir()
    line = one_line(run("eval", str(tmp_path / "absent.ply"), str(SAMPLE / "truth.png"),
                        option, str(tmp_path / name)))
    assert line.startswith(f"pcmapq: error: {tmp_path / name}: ")
    assert line.endswith(problem.format(tmp=tmp_path)), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.html"]


def test_two_outputs_on_one_file_are_refused(tmp_path):
    """An image map's --aligned PNG writes a YAML beside it: another output there is refused."""
    line = one_line(run("eval", str(SAMPLE / "truth.png"), str(SAMPLE / "truth.png"),
                        "--aligned", str(tmp_path / "a.png"), "--plot", str(tmp_path / "a.png")))
    assert f"{tmp_path / 'a.png'}: written by both --plot and --aligned" in line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args,problem", [
    (("--no-align", "--scale", "auto"), "--no-align and --scale auto"),
    (("--no-align", "--map-resolution", "auto"), "--no-align and --scale auto"),
    (("--max-scans", "3"), "--max-scans N: only with --scans DIR"),
])
def test_options_that_cannot_work_together(args, problem):
    truth = str(SAMPLE / "truth.png")
    assert problem in one_line(run("eval", truth, truth, *args))


def write_scans(folder, count: int) -> None:
    """``count`` small 3D scans (.npy) of random points."""
    folder.mkdir()
    rng = np.random.default_rng(0)
    for k in range(count):
        np.save(folder / f"{k}.npy", rng.uniform(-5, 5, size=(200, 3)))


def write_kitti(path, steps: np.ndarray) -> None:
    """KITTI poses without rotation at the given positions (K, 3), metres."""
    rows = np.zeros((len(steps), 12))
    rows[:, [0, 5, 10]] = 1.0
    rows[:, [3, 7, 11]] = steps
    np.savetxt(path, rows)


def test_map_refuses_fewer_poses_than_scans(tmp_path):
    write_scans(tmp_path / "scans", 5)
    write_kitti(tmp_path / "poses.txt", np.outer(np.arange(3), [1.0, 0, 0]))
    out = tmp_path / "m.ply"
    line = one_line(run("map", str(tmp_path / "scans"), "--poses", str(tmp_path / "poses.txt"),
                        "--out", str(out)))
    assert f"{tmp_path / 'poses.txt'}: 3 poses for 5 scans in {tmp_path / 'scans'}" in line
    assert "--max-scans 3" in line and not out.exists()
    proc = run("map", str(tmp_path / "scans"), "--poses", str(tmp_path / "poses.txt"),
               "--out", str(out), "--max-scans", "3")
    assert proc.returncode == 0, proc.stderr
    assert (f"mapping scans 0.npy to 2.npy (the first 3 of 5) of {tmp_path / 'scans'}"
            in proc.stderr) and "warning" not in proc.stderr
    assert "from 3 scans" in proc.stderr
    line = one_line(run("map", str(tmp_path / "scans"), "--poses", str(tmp_path / "poses.txt"),
                        "--out", str(out), "--max-scans", "4"))
    assert "3 poses for the first 4 scans" in line


def test_map_warns_of_camera_poses_without_calib(tmp_path):
    """Poses driving along their z axis (KITTI's camera) without --calib: one warning line;
    the same drive along x (a scanner's forward axis): none."""
    write_scans(tmp_path / "scans", 3)
    write_kitti(tmp_path / "cam.txt", np.outer(np.arange(3), [0.05, 0.02, 0.8]))
    proc = run("map", str(tmp_path / "scans"), "--poses", str(tmp_path / "cam.txt"),
               "--out", str(tmp_path / "m.ply"))
    assert proc.returncode == 0, proc.stderr
    warned = [ln for ln in proc.stderr.splitlines() if "warning" in ln]
    assert len(warned) == 1 and "cam.txt: these poses move along their z axis" in warned[0]
    assert "--calib" in warned[0]
    write_kitti(tmp_path / "lidar.txt", np.outer(np.arange(3), [0.8, 0.02, 0.05]))
    proc = run("map", str(tmp_path / "scans"), "--poses", str(tmp_path / "lidar.txt"),
               "--out", str(tmp_path / "m.ply"))
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr


def test_map_refuses_calib_without_poses_and_bad_outputs(tmp_path):
    write_scans(tmp_path / "scans", 2)
    (tmp_path / "Tr.txt").write_text(" ".join(["1 0 0 0 0 1 0 0 0 0 1 0"]) + "\n")
    line = one_line(run("map", str(tmp_path / "scans"), "--calib", str(tmp_path / "Tr.txt"),
                        "--out", str(tmp_path / "m.ply")))
    assert "Tr.txt: --calib places scans with --poses or --pose-topic only" in line
    line = one_line(run("map", str(tmp_path / "scans"), "--out", str(tmp_path / "m.las")))
    assert "m.las: --out writes .ply or .pcd, not '.las'" in line
