"""A real SLAM map, stretch by stretch: KISS-ICP's map of KITTI 00's first 20 scans against
the map of the same scans at KITTI's reference poses, both built and written as ``pcmapq map``
builds them (each point with its scan) and scored as ``pcmapq eval map.ply truth.ply
--no-noref``; the 3D consistency map's stretches of the run checked against the pose error of
KISS-ICP's own trajectory.

Scan k's error is the move E_k that takes its points from their true place (the reference
pose) to where the evaluation put them (KISS-ICP's pose, then the 3D registration), in the
truth's levelled frame: E_k = L T K_k R_k^-1 L^-1 (L the levelling, T the registration, K_k
and R_k KISS-ICP's and the reference LiDAR pose). A stretch's expected offset is the mean over
its scans of how far E_k moves its centroid c (c - E_k^-1 c: where the map has c, from its
true place), its expected turn the mean of E_k's roll, pitch and yaw. KISS-ICP deskews its
scans and the reference map does not, so a point's error is its scan's to within the motion
of one sweep. docs/validation.md's section (``bench/validation/kiss_run.py``) and
tests/realdata/test_kiss_run.py use it.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from pcmapq.io.writers import write_cloud
from pcmapq.mapping import (
    build_map_from_poses,
    build_map_kiss,
    lidar_poses_from_camera,
    read_kitti_poses,
)
from pcmapq.settings import NoRefConfig, Settings
from testkit.kitti import tr_00
from testkit.runs import Run, timed_evaluate

#: Scans of the maps (the first ones of kitti00/velodyne).
SCANS = 20
#: Scored as ``pcmapq eval map.ply truth.ply --no-noref``.
SETTINGS = Settings(noref=NoRefConfig(enabled=False))


@dataclass(frozen=True)
class Stretch:
    """One stretch of the run: its first and last scan, its expected and reported offset (dx,
    dy, dz, m) and turn (roll, pitch, yaw, deg), and whether it is held."""

    scans: tuple[int, int]
    expected_m: tuple[float, float, float]
    reported_m: tuple[float, float, float]
    expected_deg: tuple[float, float, float]
    reported_deg: tuple[float, float, float]
    held: bool

    @property
    def offset_error_m(self) -> float:
        """|reported - expected offset|, metres."""
        return float(np.linalg.norm(np.subtract(self.reported_m, self.expected_m)))

    @property
    def turn_error_deg(self) -> float:
        """The largest |reported - expected| of roll, pitch and yaw, degrees."""
        return float(np.max(np.abs(np.subtract(self.reported_deg, self.expected_deg))))


@dataclass(frozen=True)
class KissRun:
    """The evaluation of KISS-ICP's map and its stretches, in the run's order."""

    run: Run
    stretches: tuple[Stretch, ...]

    def summary(self) -> dict:
        out = self.run.summary()
        out["stretches"] = [{k: list(v) if isinstance(v, tuple) else v
                             for k, v in s.__dict__.items()} for s in self.stretches]
        return out


def _rounded(values: np.ndarray) -> tuple[float, ...]:
    return tuple(float(v) for v in np.round(values, 6) + 0.0)


def scan_errors(kiss: np.ndarray, reference: np.ndarray, transform: np.ndarray,
                level: np.ndarray | None) -> np.ndarray:
    """Each scan's error E_k (K, 4, 4) in the truth's levelled frame (the module's
    docstring): KISS-ICP's poses ``kiss`` and the reference ``reference`` (K, 4, 4, LiDAR ->
    world), the 3D registration ``transform`` (4x4) and the truth's levelling ``level``
    (3x3, None: none)."""
    turn = np.eye(4)
    if level is not None:
        turn[:3, :3] = level
    return np.array([turn @ transform @ k @ np.linalg.inv(r) @ turn.T
                     for k, r in zip(kiss, reference, strict=True)])


def measure(folder: Path) -> KissRun:
    """Both maps built and scored; each stretch's expected and reported offset and turn."""
    reference = lidar_poses_from_camera(read_kitti_poses(folder / "poses.txt"),
                                        tr_00())[:SCANS]
    kiss_map, kiss = build_map_kiss(folder / "velodyne", max_scans=SCANS)
    truth_map = build_map_from_poses(folder / "velodyne", reference, max_scans=SCANS)
    with tempfile.TemporaryDirectory(prefix="pcmapq_kiss_run_") as tmp:
        write_cloud(Path(tmp) / "map.ply", kiss_map.points, scan=kiss_map.scan)
        write_cloud(Path(tmp) / "truth.ply", truth_map.points, scan=truth_map.scan)
        run = timed_evaluate(Path(tmp) / "map.ply", Path(tmp) / "truth.ply", SETTINGS)
    r = run.result
    c, level = r.consistency_3d, r.frames.truth_levelling
    if c is None or c.scans is None:
        raise RuntimeError("KISS-ICP's map: no stretches of the run in its 3D consistency map")
    errors = scan_errors(kiss, reference, np.asarray(r.registration_3d.transform),
                         None if level is None else level.rotation)
    stretches = []
    for k, (first, last) in enumerate(c.scans.tolist()):
        moves = errors[first:last + 1]
        centre = np.append(c.centre[k], 1.0)
        offsets = [centre[:3] - (np.linalg.inv(e) @ centre)[:3] for e in moves]
        turns = Rotation.from_matrix(moves[:, :3, :3]).as_euler("xyz", degrees=True)
        stretches.append(Stretch((first, last), _rounded(np.mean(offsets, axis=0)),
                                 _rounded(c.offset[k]), _rounded(turns.mean(axis=0)),
                                 _rounded(c.angles_deg[k]), bool(c.held[k])))
    return KissRun(run, tuple(stretches))
