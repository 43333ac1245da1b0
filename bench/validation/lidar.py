"""The LiDAR registration pair: two real scans with their true transform, registered in 3D."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pcmapq.core.transform import Similarity2D
from pcmapq.settings import Settings
from testkit.realdata.lidar import pair
from testkit.runs import Run, f_at

from .common import Case, Record, Section, header, q_p, row


def cases(data: Path) -> list[Case]:
    return [Case("lidar-pair", lambda: pair(data))]


def section(data: Path, record: Record) -> Section:
    """The recovered transform against the true one, and the pair's figures."""
    run: Run = cases(data)[0].run(record)
    r, got = run.result, run.result.transform
    true_4x4 = np.loadtxt(data / "registration" / "T_target_source.txt")
    want = Similarity2D.from_matrix(true_4x4)
    reg, d3 = r.registration_3d, r.distances_3d
    if reg is None or d3 is None:
        raise RuntimeError("the LiDAR pair was not registered in 3D")
    settings = Settings()
    harris = r.detectors["harris"].matching.truth_features
    return Section("\n".join([
        "## LiDAR registration pair: two real scans with their true transform", "",
        "`registration/source.ply` and `target.ply`, two LiDAR scans, with the true 4x4 "
        "transform. Both inputs are 3D clouds, so pcmapq "
        "registers them in 3D first (FPFH + seeded RANSAC + point-to-plane ICP, voxel "
        f"{settings.alignment.voxel_3d} m, no initial guess), then scores the wall bands "
        f"({settings.raster.band_low}-{settings.raster.band_high} m above the floor) in 2D: "
        "`pcmapq eval "
        "source.ply target.ply`, default settings "
        "(`tests/realdata/test_real_maps.py::test_lidar_pair_aligns_to_its_known_transform`).", "",
        header(["", "x [m]", "y [m]", "yaw [deg]"]),
        row(["true (from the 4x4)", f"{want.tx:.4f}", f"{want.ty:.4f}", f"{want.yaw_deg:.3f}"]),
        row(["pcmapq (3D, projected to 2D)", f"{got.tx:.4f}", f"{got.ty:.4f}",
             f"{got.yaw_deg:.3f}"]), "",
        f"3D fitness {reg.fitness:.2f} (RMSE {reg.rmse_m:.3f} m), 2D fitness "
        f"{r.alignment.fitness:.2f}, coverage {r.overlap.coverage:.2f}, confidence "
        f"{r.overlap.confidence:.2f}. Every entry of the 4x4 is within "
        f"{np.abs(reg.transform - true_4x4).max():.3f} of the true one, the yaw "
        f"{abs(got.yaw_deg - want.yaw_deg):.2f} degrees. Qualities (quality / precision): "
        f"Harris {q_p(r, 'harris')} ({harris} truth corners), Hough {q_p(r, 'hough')}, SIFT "
        f"{q_p(r, 'sift')}; 3D accuracy mean {d3.accuracy.mean:.3f} m, completeness mean "
        f"{d3.completeness.mean:.3f} m, Chamfer {d3.chamfer_m:.3f} m, F@0.1 m "
        f"{f_at(r, 0.1, three_d=True):.2f}; {run.seconds:.1f} s. These are two single scans "
        "from two positions, so each sees walls the other does not: the figures describe "
        "that, not an error.",
    ]))
