"""KITTI 00 drifting vertically, for the 3D consistency map (:mod:`pcmapq.align.regions3d`):
the first scans, each cut to a short range, at the reference poses (the truth) and at poses
that drift (a pitch that integrates along the run, or scans lowered one by one), written
without their points' scans (the regions are tiles) and scored as
``pcmapq eval map.ply truth.ply``; each region's expected dz from the known true place of
every point. docs/validation.md's section (``bench/validation/consistency_3d.py``) and
tests/realdata/test_consistency_3d_kitti.py use it."""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.transform import affine
from pcmapq.core.voxels import voxel_groups
from pcmapq.io.writers import write_cloud
from pcmapq.mapping import build_map_from_poses, lidar_poses_from_camera, read_kitti_poses
from pcmapq.mapping.reference import scans_for_poses
from pcmapq.settings import AlignmentConfig, MatchingConfig, NoRefConfig, Settings
from testkit.kitti import tr_00
from testkit.runs import timed_evaluate

#: Scans, and the range each is cut to, metres.
SCANS, RANGE_M = 20, 12.0
#: The ladders: degrees of pitch added per step, metres lowered per scan.
LADDERS = (("pitch", (0.05, 0.1, 0.2, 0.4)), ("lower", (0.005, 0.01, 0.02, 0.04)))
#: Scored with --force, no detectors and no no-reference figures: the 3D figures alone.
SETTINGS = Settings(alignment=AlignmentConfig(force=True), matching=MatchingConfig(detectors=()),
                    noref=NoRefConfig(enabled=False))
#: The issue's bound: the reported dz within this many metres plus a share of the injected
#: offset of the expected one.
WITHIN_M, WITHIN_SHARE = 0.05, 0.1


@dataclass(frozen=True)
class Rung:
    """One drifted map: the vertical offset injected at the last scan (m), the 3D registration's
    fitness, regions and held regions, the held region where the expected |dz| is largest (its
    centroid x, y, its expected and reported dz, m), the largest reported |dz| (signed) and
    whether it is that region, the median and largest |reported - expected| over the held
    regions (m), the seconds of the evaluation and of its 3D consistency step."""

    kind: str
    level: float
    injected_m: float
    fitness: float
    regions: int
    held: int
    far_at: tuple[float, float]
    expected_m: float
    reported_m: float
    largest_m: float
    same_region: bool
    median_error_m: float
    max_error_m: float
    seconds: float

    def summary(self) -> dict:
        return {k: v for k, v in self.__dict__.items() if k != "seconds"}

    @property
    def within(self) -> bool:
        return abs(self.reported_m - self.expected_m) <= \
            WITHIN_M + WITHIN_SHARE * abs(self.injected_m)


def _turn_y(degrees: float) -> np.ndarray:
    """4x4 turn about y (the LiDAR's lateral axis, to its left): +x goes down for > 0."""
    a = np.radians(degrees)
    out = np.eye(4)
    out[0, 0] = out[2, 2] = np.cos(a)
    out[0, 2], out[2, 0] = np.sin(a), -np.sin(a)
    return out


def drifted(poses: np.ndarray, kind: str, level: float) -> np.ndarray:
    """The poses (K, 4, 4) drifted: ``pitch`` turns each step's motion by ``level`` degrees
    more about the lateral axis; ``lower`` lowers pose k by k x ``level`` metres."""
    if kind == "lower":
        out = poses.copy()
        out[:, 2, 3] -= level * np.arange(len(poses))
        return out
    out = [poses[0]]
    for k in range(1, len(poses)):
        out.append(out[-1] @ _turn_y(level) @ np.linalg.inv(poses[k - 1]) @ poses[k])
    return np.array(out)


def expected_dz(scans: list[np.ndarray], truth: np.ndarray, drift: np.ndarray,
                place: np.ndarray, level: np.ndarray | None, centre: np.ndarray, tile: float,
                voxel: float) -> np.ndarray:
    """Each region's expected dz (K,), metres: every point of every scan where the evaluation
    placed it (``place`` @ drift pose, then levelled) less where it truly is (reference pose,
    levelled), averaged over each voxel of its placed position, then over the voxels of the
    region's tile (``centre`` (K, 3): the regions' centroids)."""
    placed, error = placed_errors(scans, truth, drift, place, level)
    return region_dz(placed, error[:, 2], centre, tile, voxel)


def placed_errors(scans: list[np.ndarray], truth: np.ndarray, drift: np.ndarray,
                  place: np.ndarray, level: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Every point of every scan where the evaluation placed it (``place`` @ drift pose, then
    levelled by ``level``, 3x3 or None) and its error there (placed less true: at the
    reference pose, levelled), both (N, 3) metres."""
    turn = np.eye(3) if level is None else np.asarray(level)
    placed = np.vstack([affine(p, place @ d) for p, d in zip(scans, drift, strict=True)])
    true = np.vstack([affine(p, t) for p, t in zip(scans, truth, strict=True)])
    return placed @ turn.T, (placed - true) @ turn.T


def region_dz(placed: np.ndarray, dz: np.ndarray, centre: np.ndarray, tile: float,
              voxel: float) -> np.ndarray:
    """Each region's mean vertical error (K,), metres: the points' (N, 3, placed) errors
    ``dz`` (N,) averaged over each voxel, then over the voxels in the region's tile."""
    _, voxel_of = voxel_groups(placed, voxel)
    n = np.bincount(voxel_of)
    mean_dz = np.bincount(voxel_of, dz) / n
    xy = np.column_stack([np.bincount(voxel_of, placed[:, i]) / n for i in range(2)])
    tile_of = np.floor(xy / tile).astype(np.int64)
    wanted = np.floor(centre[:, :2] / tile).astype(np.int64)
    return np.array([mean_dz[np.all(tile_of == t, axis=1)].mean() for t in wanted])


def stretch_dz(placed: np.ndarray, dz: np.ndarray, stretch_of: np.ndarray,
               wanted: np.ndarray, voxel: float) -> np.ndarray:
    """Each stretch's mean vertical error (K,), metres: the points' (N, 3, placed) errors
    ``dz`` (N,) averaged over each voxel of a stretch's points (``stretch_of`` (N,) each
    point's stretch), then over the stretch's voxels, for the stretches ``wanted`` (K,)."""
    out = []
    for k in wanted:
        mine = stretch_of == k
        _, voxel_of = voxel_groups(placed[mine], voxel)
        out.append(float(np.mean(np.bincount(voxel_of, dz[mine]) / np.bincount(voxel_of))))
    return np.array(out)


def measure(folder: Path, kind: str, level: float) -> Rung:
    """The reference map and the drifted one, scored; the rung's figures."""
    truth = lidar_poses_from_camera(read_kitti_poses(folder / "poses.txt"), tr_00())[:SCANS]
    drift = drifted(truth, kind, level)
    scans = [p[np.linalg.norm(p, axis=1) <= RANGE_M]
             for p, _ in scans_for_poses(folder / "velodyne", SCANS, max_scans=SCANS)]
    with tempfile.TemporaryDirectory(prefix="pcmapq_bends_") as tmp:
        for name, poses in (("truth", truth), ("map", drift)):
            write_cloud(Path(tmp) / f"{name}.ply", build_map_from_poses(
                folder / "velodyne", poses, max_scans=SCANS, max_range=RANGE_M).points)
        run = timed_evaluate(Path(tmp) / "map.ply", Path(tmp) / "truth.ply", SETTINGS)
    r = run.result
    c, level_of = r.consistency_3d, r.frames.truth_levelling
    if c is None or r.registration_3d is None or not c.held.any():
        raise RuntimeError(f"{kind} {level}: no held region of a 3D consistency map")
    expected = expected_dz(scans, truth, drift, r.registration_3d.transform,
                           None if level_of is None else level_of.rotation, c.centre, c.tile_m,
                           c.voxel_m)
    far = int(np.flatnonzero(c.held)[np.argmax(np.abs(expected[c.held]))])
    largest = c.largest_dz()
    gap = np.abs(c.offset[c.held, 2] - expected[c.held])
    return Rung(kind, level, float(drift[-1, 2, 3] - truth[-1, 2, 3]), r.registration_3d.fitness,
                len(c.points), int(c.held.sum()), tuple(np.round(c.centre[far, :2], 1).tolist()),
                round(float(expected[far]), 6), float(c.offset[far, 2]),
                float(c.offset[largest, 2]), largest == far, round(float(np.median(gap)), 6),
                round(float(gap.max()), 6), run.seconds)

