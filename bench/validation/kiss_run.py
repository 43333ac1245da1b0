"""A real SLAM map, stretch by stretch: KISS-ICP's map of KITTI 00's first 20 scans against the
map at KITTI's reference poses, its 3D consistency map's stretches of the run against the pose
error of KISS-ICP's own trajectory (:mod:`testkit.realdata.kiss_run`).

    python -m bench.validation --only kiss_run
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from testkit.realdata.kiss_run import SCANS, KissRun, measure

from .common import Case, Record, Section


def cases(data: Path) -> list[Case]:
    return [Case("kiss-run-kitti00", lambda: measure(data / "kitti00"))]


def _three(values: tuple[float, float, float], digits: int) -> str:
    return ", ".join(f"{v:+.{digits}f}" for v in values)


def section(data: Path, record: Record) -> Section:
    measured: KissRun = cases(data)[0].run(record)
    r, stretches = measured.run.result, measured.stretches
    rows = [f"| {s.scans[0]}-{s.scans[1]} | {_three(s.expected_m, 3)} | "
            f"{_three(s.reported_m, 3)} | {s.offset_error_m:.3f} | "
            f"{_three(s.expected_deg, 2)} | {_three(s.reported_deg, 2)} | "
            f"{s.turn_error_deg:.2f} | {'yes' if s.held else 'no'} |" for s in stretches]
    held = [s for s in stretches if s.held]
    expected = [float(np.linalg.norm(s.expected_m)) for s in held]
    reported = [float(np.linalg.norm(s.reported_m)) for s in held]
    far, most = held[int(np.argmax(expected))], held[int(np.argmax(reported))]
    c = r.consistency_3d
    return Section("\n".join([
        "## A SLAM map, stretch by stretch: KISS-ICP on KITTI 00", "",
        f"KISS-ICP's map of the first {SCANS} scans of `kitti00/velodyne` (the map) against the "
        "same scans at KITTI's reference poses (the truth), both built and written as `pcmapq "
        "map` builds them, each point with its scan, and scored as `pcmapq eval map.ply "
        "truth.ply --no-noref`: the 3D consistency map cuts the map into stretches of "
        f"{c.stretch} scans, each registered to the truth on its own "
        "(docs/metrics.md#3d-consistency-map-consistency_3d-in-the-json---regions-3d-csv). "
        "KISS-ICP's own trajectory says what to expect: scan k's error is the move that takes "
        "its points from their true place (the reference pose) to where the evaluation put "
        "them (KISS-ICP's pose, then the 3D registration), in the truth's levelled frame; a "
        "stretch's *expected* offset is the mean over its scans of how far that move carries "
        "the stretch's centroid, its expected turn the mean of the moves' roll, pitch and yaw "
        "(`testkit/realdata/kiss_run.py`). KISS-ICP deskews its scans and the reference map "
        "does not, so a point's error is its scan's to within the motion of one sweep.", "",
        "| scans | expected dx, dy, dz (m) | reported dx, dy, dz (m) | offset error (m) | "
        "expected roll, pitch, yaw (deg) | reported roll, pitch, yaw (deg) | "
        "largest turn error (deg) | held |",
        "| --- | --- | --- | ---: | --- | --- | ---: | --- |", *rows, "",
        f"The whole map: 3D registration fitness {r.registration_3d.fitness:.3f}, Chamfer 3D "
        f"{r.distances_3d.chamfer_m:.3f} m. Stretch by stretch, KISS-ICP's map is off most "
        f"at scans {far.scans[0]}-{far.scans[1]}, {expected[held.index(far)]:.2f} m and "
        f"{abs(far.expected_deg[2]):.2f} degrees of yaw by its own trajectory; the "
        f"consistency map reports scans {most.scans[0]}-{most.scans[1]} "
        f"({reported[held.index(most)]:.2f} m, {abs(most.reported_deg[2]):.2f} degrees), "
        f"every held stretch ({len(held)} of {len(stretches)}) within "
        f"{max(s.offset_error_m for s in held):.2f} m and "
        f"{max(s.turn_error_deg for s in held):.2f} degrees of what its scans' pose errors "
        "put there.",
    ]))
