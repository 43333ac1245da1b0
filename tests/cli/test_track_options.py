"""`pcmapq track`'s options checked before any work: --calib without reference poses is refused
in one line."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app

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
