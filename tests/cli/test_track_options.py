"""`pcmapq track`'s options refused in one line: --calib without reference poses (before any
work), a --footprint the run's maps cannot follow (as eval refuses it)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.io import load_map
from testkit.carmen import flaser_log
from testkit.paths import SAMPLE
from testkit.recordings import write_recording

#: KITTI odometry sequence 00's Tr (velodyne -> left camera), row-major 3x4
#: (../shared/README.md).
TR = np.array([4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03,
               -1.198459927713e-02, -7.210626507497e-03, 8.081198471645e-03,
               -9.999413164504e-01, -5.403984729748e-02, 9.999738645903e-01,
               4.859485810390e-04, -7.206933692422e-03, -2.921968648686e-01])


@pytest.mark.unit
def test_calib_without_reference_poses_is_refused(tmp_path) -> None:
    calib = tmp_path / "Tr.txt"
    np.savetxt(calib, TR.reshape(3, 4))
    got = CliRunner().invoke(app, ["track", str(tmp_path / "run.log"), str(tmp_path / "t.png"),
                                   "--out", str(tmp_path / "o"), "--calib", str(calib)])
    assert got.exit_code == 2, got.stderr
    assert got.stderr.count("\n") == 1 and str(calib) in got.stderr, got.stderr


def _log(tmp_path: Path) -> Path:
    """A CARMEN log of three scans in the sample's hall (its map: a cloud of the scans' views;
    ranges of 2 to 4 m, none the log's "no return" code)."""
    poses = np.array([[6.0, 8.0, 0.0], [6.5, 8.0, 0.0], [7.0, 8.0, 0.0]])
    ranges = np.tile(np.linspace(2.0, 4.0, 181), (3, 1))
    return flaser_log(tmp_path / "run.log", ranges, poses)


def _recording(tmp_path: Path) -> Path:
    """A recording of one published map: the sample's truth (an image, no scans' views)."""
    truth = load_map(SAMPLE / "truth.yaml")
    return write_recording(tmp_path / "run.mcap", [(1.0, truth.state, truth.grid)], "mcap")


@pytest.mark.parametrize(("make", "rule"), [(_log, "known"), (_recording, "seen")],
                         ids=["cloud-known", "image-seen"])
def test_a_footprint_rule_the_maps_cannot_follow_is_refused_as_eval_refuses_it(
        tmp_path, make, rule) -> None:
    """A run whose maps cannot follow ``--footprint`` (a cloud has no known cells, an image no
    scans' views) is refused by track with eval's line and exit code, not scored into steps
    that each note it."""
    run_path, truth = make(tmp_path), str(SAMPLE / "truth.png")
    runner = CliRunner()
    evaluated = runner.invoke(app, ["eval", str(run_path), truth, "--footprint", rule])
    tracked = runner.invoke(app, ["track", str(run_path), truth, "--footprint", rule,
                                  "--out", str(tmp_path / "out")])
    assert evaluated.exit_code == 2, evaluated.stderr
    line, = evaluated.stderr.strip().splitlines()
    assert line.startswith(f"pcmapq: error: {run_path}: ") and rule in line, line
    assert tracked.exit_code == 2, tracked.stderr
    assert tracked.stderr.strip() == line
    assert not (tmp_path / "out").exists()
