"""No-reference figures against the truth: do they rank maps by drift as the ground truth does?

2D, on the CARMEN drift ladders (:mod:`testkit.drift`): each rung's scans along their
drifted poses are ray-cast into an occupancy grid (:func:`raycast_state`) and scored by
:func:`pcmapq.metrics.noref2d.grid_scores`, beside the rung's figures against the corrected map.
3D, on the first KITTI 00 scans: maps from KITTI's reference poses, from KISS-ICP's poses and
from the reference poses with a yaw drift per metre (:func:`yaw_drifted`), voxel-downsampled
alike and scored by MME, MPV and MOM (:func:`pcmapq.metrics.inspection.noref_figures`), beside
``pcmapq eval`` of each map against the reference map. Each figure's Spearman rank correlation
with the drift level says whether it ranks the maps as the drift does (+1: it grows with the
drift, as it should; every figure here is lower-is-better). Then the real 2D maps of the other
sections beside their truths (:mod:`bench.validation.noref_grids`).
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from scipy.stats import spearmanr

from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.grid import MetricGrid
from pcmapq.core.voxels import voxel_centroids
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints
from pcmapq.io.writers import write_cloud
from pcmapq.mapping import build_map_from_poses, lidar_poses_from_camera, read_kitti_poses
from pcmapq.mapping.kiss import build_map_kiss
from pcmapq.mapping.scans import open_scans
from pcmapq.metrics.inspection import noref_figures
from pcmapq.metrics.noref2d import grid_scores
from pcmapq.metrics.orthogonal import extract_orthogonal_subset
from pcmapq.raster.draw import hit_counts
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from testkit import drift
from testkit.runs import Run, f_at, timed_evaluate

from . import carmen, noref_grids
from .common import Case, Record, Section, header, row
from .kitti import TR

#: Cell of the ray-cast CARMEN grids, metres (pcmapq's cloud resolution).
RESOLUTION = 0.05
#: KITTI: scans of the maps, yaw drift levels (degrees per metre travelled), seed.
SCANS = 20
YAW_LEVELS = (0.0, 0.05, 0.1, 0.2, 0.5, 1.0)
SEED = 0
#: KITTI: the voxel every map is downsampled to before MME/MPV/MOM, and their neighbourhood.
VOXEL = 0.3
RADIUS, MIN_KNN, MAX_NN = 1.0, 5, 30
#: ``pcmapq eval`` of the KITTI maps: the 3D figures only (no 2D detectors), alignment forced.
EVAL_SETTINGS = Settings(alignment=AlignmentConfig(force=True),
                         matching=MatchingConfig(detectors=()))
#: The figures of each table, lower-is-better, as (label, key).
GRID_FIGURES = (("occupied", "occupied_cells"), ("free", "free_cells"),
                ("occ/free", "occupied_free_ratio"), ("corners", "corners"),
                ("enclosed", "enclosed_areas"), ("enclosed m²", "enclosed_area_m2"))
NOREF_FIGURES = (("MME", "mme"), ("MPV", "mpv"), ("MOM", "mom"))


def raycast_state(poses: np.ndarray, ranges: np.ndarray, angles: np.ndarray,
                  max_range: float = DEFAULT_MAX_RANGE,
                  resolution: float = RESOLUTION) -> tuple[np.ndarray, MetricGrid]:
    """An occupancy raster of 2D scans at poses: OCCUPIED where a beam ends (readings up to
    ``max_range`` metres), FREE where a scan's fan reaches and no beam ends, UNKNOWN elsewhere.

    A scan's fan is the polygon from its pose through its beams' ends in beam order (one
    ``cv2.fillPoly`` per scan, 8 fixed-point bits): readings above ``max_range`` are cut to it
    (free up to there, no end), beams without a reading (NaN) are left out of the polygon.
    poses (K, 3) x, y metres, theta radians; ranges (K, B) metres; angles (K, B) or (B,)."""
    hits = endpoints(poses, ranges, angles, max_range)
    heading = poses[:, 2:3] + np.broadcast_to(angles, ranges.shape)
    reach = np.minimum(ranges, max_range)
    ends = np.stack([poses[:, 0:1] + reach * np.cos(heading),
                     poses[:, 1:2] + reach * np.sin(heading)], axis=-1)
    ok = np.isfinite(ends).all(axis=-1)
    grid = MetricGrid.covering(np.vstack([ends[ok], poses[:, :2]]), resolution)
    shift = 8
    scale = float(1 << shift)
    uv = np.round(grid.xy_to_pixels(np.nan_to_num(ends).reshape(-1, 2)) * scale)
    uv = uv.astype(np.int32).reshape(ends.shape)
    origin = np.round(grid.xy_to_pixels(poses[:, :2]) * scale).astype(np.int32)
    fan = np.zeros(grid.shape, np.uint8)
    for k in range(len(poses)):  # one polygon per scan: overlapping fans are all filled
        cv2.fillPoly(fan, [np.vstack([origin[k:k + 1], uv[k][ok[k]]])], 1,
                     lineType=cv2.LINE_8, shift=shift)
    state = np.full(grid.shape, UNKNOWN, np.int8)
    state[fan > 0] = FREE
    state[hit_counts(hits, grid) > 0] = OCCUPIED
    return state, grid


@dataclass(frozen=True)
class GridRung:
    """One CARMEN rung: its figures against the corrected map and its no-reference figures."""

    truth: drift.Rung
    grid: dict

    def summary(self) -> dict:
        return {"level": self.truth.level, "grid": self.grid, "truth": self.truth.figures}


@dataclass(frozen=True)
class Ladder:
    """The rungs of one ladder (the cases' measured value)."""

    rungs: list

    def summary(self) -> dict:
        return {"rungs": [r.summary() for r in self.rungs]}


def grid_rung(log: Path, level: float) -> GridRung:
    """A CARMEN rung: ``drift.rung`` and the grid figures of its ray-cast map."""
    poses, ranges, angles = drift._scans(log, None)
    state, grid = raycast_state(drift.drifted(poses, level, carmen.SEED), ranges, angles)
    return GridRung(drift.rung(log, level, carmen.SEED), asdict(grid_scores(state, grid)))


def grid_ladder(log: Path) -> Ladder:
    return Ladder([grid_rung(log, level) for level in carmen.LEVELS])


def rotz(angle: np.ndarray) -> np.ndarray:
    """(K, 4, 4) rotations about z by ``angle`` (K,) radians."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.tile(np.eye(4), (len(angle), 1, 1))
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
    return out


def yaw_drifted(poses: np.ndarray, deg_per_m: float, seed: int = SEED) -> np.ndarray:
    """The trajectory ``poses`` (K, 4, 4; sensor -> world, z up) integrated again from its first
    pose with a yaw error after each step: each relative motion inv(P_k) P_k+1 is followed by a
    turn about the sensor's z of ``deg_per_m * (1 + z_k)`` degrees per metre of the step
    (z ~ N(0, 1), seeded: a systematic rate plus a random one of the same size, as
    :func:`testkit.drift.drifted`). 0 gives ``poses`` back (up to rounding)."""
    rel = np.linalg.inv(poses[:-1]) @ poses[1:]
    step = np.linalg.norm(rel[:, :3, 3], axis=1)
    z = np.random.default_rng(seed).standard_normal(len(rel))
    rel = rel @ rotz(np.radians(deg_per_m * (1.0 + z) * step))
    out = [poses[0]]
    for motion in rel:  # K matrix products (K scans), not a loop over points
        out.append(out[-1] @ motion)
    return np.stack(out)


@dataclass(frozen=True)
class CloudRung:
    """One KITTI map: its drift (None for KISS-ICP's poses), how far its poses are from the
    reference's (largest position distance, metres; largest yaw difference, degrees), its
    no-reference figures and its evaluation against the reference map."""

    label: str
    level: float | None
    pose_error_m: float
    yaw_error_deg: float
    noref: dict
    run: Run

    def summary(self) -> dict:
        return {"label": self.label, "level": self.level, "noref": self.noref,
                "eval": self.run.summary()}


@dataclass(frozen=True)
class CloudLadder:
    """The KITTI maps of one ladder (the drifts of its ``base`` trajectory, then the other
    trajectory) and the seconds of the whole case."""

    base: str
    rungs: list[CloudRung]
    seconds: float

    def summary(self) -> dict:
        return {"rungs": [r.summary() for r in self.rungs]}


def pose_errors(poses: np.ndarray, reference: np.ndarray) -> tuple[float, float]:
    """Largest distance (metres) and yaw difference (degrees) of two (K, 4, 4) trajectories."""
    rel = np.linalg.inv(reference) @ poses
    yaw = np.degrees(np.abs(np.arctan2(rel[:, 1, 0], rel[:, 0, 0])))
    return (float(np.max(np.linalg.norm(poses[:, :3, 3] - reference[:, :3, 3], axis=1))),
            float(np.max(yaw)))


@lru_cache(maxsize=1)
def trajectories(folder: Path) -> dict[str, np.ndarray]:
    """The first ``SCANS`` poses of KITTI's reference (in the first LiDAR frame) and of
    KISS-ICP (its own run over the scans), (K, 4, 4) each, by name."""
    reference = lidar_poses_from_camera(read_kitti_poses(folder / "poses.txt"),
                                        np.vstack([TR, [0, 0, 0, 1]]))[:SCANS]
    _, kiss = build_map_kiss(folder / "velodyne", max_scans=SCANS)
    return {"reference": reference, "KISS-ICP": kiss}


def cloud_ladder(folder: Path, base: str) -> CloudLadder:
    """The KITTI maps of one ladder: the raw scans placed along the ``base`` trajectory
    ('reference' or 'KISS-ICP') with each yaw drift, then along the other trajectory
    (``build_map_from_poses``, 0.1 m voxel, as ``pcmapq map --poses``); each downsampled to
    ``VOXEL`` for MME/MPV/MOM (MOM's planes extracted once from the first scan at ``VOXEL``: it
    sits at the identity in every map) and ``pcmapq eval``-ed against the undrifted map."""
    start = time.perf_counter()
    velodyne = folder / "velodyne"
    paths = trajectories(folder)
    first = voxel_centroids(next(iter(open_scans(velodyne)))[0], VOXEL)
    planes = extract_orthogonal_subset(first, RADIUS, MAX_NN)
    other = next(name for name in paths if name != base)
    runs = [(f"{base} + {level:g} °/m", level, yaw_drifted(paths[base], level))
            for level in YAW_LEVELS] + [(other, None, paths[other])]
    rungs = []
    with tempfile.TemporaryDirectory(prefix="pcmapq_noref_") as tmp:
        truth = Path(tmp) / "truth.ply"
        for label, level, poses in runs:
            cloud = build_map_from_poses(velodyne, poses, max_scans=SCANS).points
            path = truth if level == 0 else Path(tmp) / "map.ply"
            write_cloud(path, cloud)
            figures = noref_figures(voxel_centroids(cloud, VOXEL), RADIUS, MIN_KNN, MAX_NN,
                                    planes)
            rungs.append(CloudRung(label, level, *pose_errors(poses, paths[base]), figures,
                                   timed_evaluate(path, truth, EVAL_SETTINGS)))
    return CloudLadder(base, rungs, time.perf_counter() - start)


def cases(data: Path) -> list[Case]:
    return [Case(f"noref-carmen-{log.split('-')[0]}",
                 lambda log=log: grid_ladder(data / "carmen" / log)) for log in carmen.LOGS] + [
        Case(f"noref-kitti00-{base.split('-')[0].lower()}",
             lambda base=base: cloud_ladder(data / "kitti00", base))
        for base in ("reference", "KISS-ICP")] + noref_grids.cases(data)


def rho(levels: Sequence[float], values: Sequence[float | None]) -> float | None:
    """Spearman's rank correlation of some figures with the drift levels (None figures left
    out; None when fewer than 3 remain or the figures are all equal)."""
    pairs = [(a, b) for a, b in zip(levels, values, strict=True)
             if b is not None and math.isfinite(b)]
    if len(pairs) < 3 or len({b for _, b in pairs}) < 2:
        return None
    value = float(spearmanr(*zip(*pairs, strict=True)).statistic)
    return value if math.isfinite(value) else None


def fmt(value: float | None, digits: int = 3) -> str:
    """A figure: '-' for None, integers as they are, else ``digits`` significant digits."""
    if value is None:
        return "-"
    if isinstance(value, int):
        return str(value)
    return f"{value:.{digits}g}" if abs(value) < 1e-2 and value != 0 else f"{value:.{digits}f}"


def correlations(levels: Sequence[float], columns: dict[str, list]) -> dict[str, float | None]:
    """Each column's Spearman rho with the levels."""
    return {label: rho(levels, values) for label, values in columns.items()}


def rho_line(found: dict[str, float | None]) -> str:
    return "; ".join(f"{label} {fmt(value, 2) if value is not None else '-'}"
                     for label, value in found.items())


def peak(ladder: Ladder, key: str) -> float:
    """The drift level where a grid figure is largest."""
    return max(ladder.rungs, key=lambda r: r.grid[key] or 0).truth.level


def grid_table(ladder: Ladder) -> tuple[list[str], dict[str, float | None]]:
    """A CARMEN ladder's table and the rho of every figure (no-reference and truth)."""
    rungs: list[GridRung] = ladder.rungs
    names = list(rungs[0].truth.f1)
    lines = [header(["drift %", "max pose err m", *[f"f1 {n}" for n in names], "Chamfer m",
                     "F@0.1", *[label for label, _ in GRID_FIGURES]])]
    for r in rungs:
        t = r.truth
        lines.append(row([f"{100 * t.level:g}", f"{t.pose_error_m:.2f}",
                          *[fmt(t.f1[n]) for n in names], fmt(t.chamfer_m), fmt(t.f_at_01),
                          *[fmt(r.grid[key]) for _, key in GRID_FIGURES]]))
    levels = [r.truth.level for r in rungs]
    columns = {label: [r.grid[key] for r in rungs] for label, key in GRID_FIGURES}
    columns |= {f"f1 {n}": [r.truth.f1[n] for r in rungs] for n in names}
    columns["Chamfer"] = [r.truth.chamfer_m for r in rungs]
    return lines, correlations(levels, columns)


def bracket(value: float, values: Sequence[float], levels: Sequence[float]) -> str:
    """Between which levels a figure falls on a ladder whose figures grow: 'a-b °/m', or
    'more than' / 'less than' the ends."""
    above = [lv for v, lv in zip(values, levels, strict=True) if v >= value]
    below = [lv for v, lv in zip(values, levels, strict=True) if v < value]
    if not above:
        return f"more than {max(levels):g} °/m"
    if not below:
        return f"less than {min(levels):g} °/m"
    return f"{max(below):g}-{min(above):g} °/m"


def cloud_table(ladder: CloudLadder) -> tuple[list[str], dict[str, float | None]]:
    """The KITTI maps' table and the rho (over the drift ladder, not KISS-ICP) of each figure."""
    lines = [header(["poses", "max pose err m", "max yaw err deg", "points", "MME nats",
                     "MPV m²", "MOM m²", "3D fitness", "3D acc mean m", "3D comp mean m",
                     "3D Chamfer m", "3D F@0.2"])]
    truth: dict[str, Callable[[CloudRung], float | None]] = {
        "3D fitness": lambda r: r.run.result.registration_3d.fitness,
        "3D acc mean": lambda r: r.run.result.distances_3d.accuracy.mean,
        "3D comp mean": lambda r: r.run.result.distances_3d.completeness.mean,
        "3D Chamfer": lambda r: r.run.result.distances_3d.chamfer_m,
        "3D F@0.2": lambda r: f_at(r.run.result, 0.2, three_d=True),
    }
    for r in ladder.rungs:
        lines.append(row([r.label, f"{r.pose_error_m:.2f}", f"{r.yaw_error_deg:.2f}",
                          f"{r.noref['points']:,}",
                          *[fmt(r.noref[key], 4) for _, key in NOREF_FIGURES],
                          *[fmt(get(r)) for get in truth.values()]]))
    ladder_rungs = [r for r in ladder.rungs if r.level is not None]
    columns = {label: [r.noref[key] for r in ladder_rungs] for label, key in NOREF_FIGURES}
    columns |= {label: [get(r) for r in ladder_rungs] for label, get in truth.items()}
    return lines, correlations([r.level for r in ladder_rungs], columns)


def section(data: Path, record: Record) -> Section:
    """Both ladders' tables, their rank correlations, and what they show."""
    got = [case.run(record) for case in cases(data)]
    n = len(carmen.LOGS)
    grids, clouds, pairs = got[:n], got[n:n + 2], got[n + 2:]
    lines = [
        "## No-reference figures against the truth: do they rank maps by drift?", "",
        "Every no-reference figure is lower-is-better, so one that ranks maps as the drift does "
        "grows with it: its Spearman rank correlation with the drift level (`scipy.stats."
        "spearmanr`, rho) is +1. The truth's figures are beside them for comparison (f1 and F "
        "should fall, rho -1; distances grow, rho +1).", "",
        "### 2D: the CARMEN drift ladders, ray-cast", "",
        "The rungs of the CARMEN section (the same drifted poses and figures against the "
        f"corrected map). Each rung's map is ray-cast at {RESOLUTION:g} m "
        "(`bench.validation.noref.raycast_state`): occupied where a beam ends (readings up to "
        f"{DEFAULT_MAX_RANGE:g} m), free inside each scan's fan (its pose and its beams' ends in "
        "order, longer readings cut to the max range, beams without a reading left out; one "
        "`cv2.fillPoly` per scan), unknown elsewhere; then `pcmapq.metrics.noref2d.grid_scores`. "
        "The occupied cells and corners need only the endpoints (a cloud map); the free cells, "
        "the ratio and the enclosed areas need the rays. MME "
        "and MPV are not computed: the 2D points lie in one plane (z = 0).",
    ]
    found_all = []
    for log, ladder in zip(carmen.LOGS, grids, strict=True):
        table, found = grid_table(ladder)
        found_all.append(found)
        lines += ["", f"#### {log}", "", *table, "", "Spearman rho with the drift level: "
                  + rho_line(found) + "."]
    labels = [label for label, _ in GRID_FIGURES]
    good = [x for x in labels if all((f[x] or 0) >= 0.9 for f in found_all)]
    peaks = ", ".join(f"{log.split('-')[0]} {100 * peak(ladder, 'occupied_free_ratio'):g} %"
                      for log, ladder in zip(carmen.LOGS, grids, strict=True))
    lines += [
        "", f"Rho at least 0.9 on both logs: {', '.join(good) or 'none'}; the others rank "
        f"only roughly. The occupied/free ratio is largest at {peaks} of drift and falls "
        "after: the drifted scans' fans spread free space over more new cells than their "
        "smeared walls add occupied ones. Occupied cells and corners rank the rungs best, but they "
        "also grow with how much of a place is mapped: they compare maps of the same scans only.",
        "", *noref_grids.section_lines(pairs),
    ]
    first = clouds[0].rungs[0].noref["orth_plane_points"]
    lines += [
        "", "### 3D: KITTI 00, yaw drift on two trajectories", "",
        f"The first {SCANS} scans of `kitti00/velodyne` placed with `build_map_from_poses` "
        "(0.1 m voxel, as `pcmapq map --poses`; raw scans, not deskewed, so every map holds the "
        "same points and only the poses differ) along a base trajectory with a yaw drift of e "
        "degrees per metre (`bench.validation.noref.yaw_drifted`: after each step a turn about "
        f"the sensor's z of e (1 + z) degrees per metre of the step, z ~ N(0, 1), seed {SEED}). "
        "Two bases: KITTI's reference poses (in the first LiDAR frame) and KISS-ICP's poses "
        "(its run over the same scans); each table ends with the map of the other base, off "
        f"the ladder. Every map is downsampled to one point per {VOXEL:g} m voxel for MME, MPV "
        f"and MOM (radius {RADIUS:g} m, min_knn {MIN_KNN}; the same voxel for every map, since "
        "MME depends on density); MOM's orthogonal planes are extracted once from the first "
        "scan at that voxel (it sits at the identity in every map; "
        f"{', '.join(str(n) for n in first)} points). The truth's figures are `pcmapq eval MAP "
        "BASE.ply` on the 0.1 m maps (3D figures only, `force`): its 3D registration takes out "
        "the mean error, so they measure what drift leaves after the best rigid fit.",
    ]
    for cloud in clouds:
        table, found = cloud_table(cloud)
        off = cloud.rungs[-1]
        lines += ["", f"#### Base: {cloud.base} poses ({cloud.seconds:.0f} s)", "", *table, "",
                  "Spearman rho with the drift level (the base's maps): " + rho_line(found)
                  + f". The {off.label} map is {off.pose_error_m:.2f} m and "
                  f"{off.yaw_error_deg:.2f} degrees of yaw from the base at most."]
    ref, kiss = (c.rungs[0].noref for c in clouds)
    kiss_ladder = clouds[1].rungs[:-1]
    off = clouds[0].rungs[-1].run.result.distances_3d
    like = bracket(ref["mme"], [r.noref["mme"] for r in kiss_ladder],
                   [r.level for r in kiss_ladder])
    lines += [
        "", f"The reference-pose map scores like the KISS-ICP map with {like} of yaw drift "
        f"(MME {ref['mme']:.3f} against {kiss['mme']:.3f} undrifted, MPV {ref['mpv']:.4f} "
        f"against {kiss['mpv']:.4f}, MOM {fmt(ref['mom'])} against {fmt(kiss['mom'])}, "
        f"{ref['points']:,} voxels against {kiss['points']:,} for the same points), and "
        "every no-reference figure prefers the KISS-ICP map. This agrees with the KITTI "
        "section (KITTI's reference poses move at constant speed over these frames while the "
        "car accelerates, so they smear the scans), which `pcmapq eval` against the reference "
        f"map cannot see: there the KISS-ICP map's 3D Chamfer distance ({fmt(off.chamfer_m)} m) "
        "is that of a drifted map. But a crisp map is not a right one: ICP odometry minimises "
        "the very misalignment between scans that these figures measure, so they favour it "
        "by construction.",
    ]
    return Section("\n".join(lines))
