"""KITTI 00's 3D drift ladders (issue 57): the map of its first 20 scans at KITTI's reference
poses (the truth) and maps of the same scans at poses that drift as odometry drifts, each
error integrated along the run, at five levels of three kinds:

- heading: each step's motion turned a further *level* degrees about the scanner's vertical
  axis (scan k turned k x level, the run curving sideways; :func:`testkit.kitti.curved`);
- vertical: the same about its lateral axis (a pitch drift: the run bends down);
- scale: each step's translation (1 + *level*) as long (the run stretches;
  :func:`testkit.kitti.stretched`).

All built as ``pcmapq map --poses`` builds them (:func:`pcmapq.mapping.build_map_from_poses`:
full range, 0.1 m voxels, each point with its scan, so that the 3D consistency map's regions are
stretches of the run; each map once per process) and scored as ``pcmapq eval map.ply truth.ply
--no-noref`` scores two 3D clouds.

The levels, measured (KITTI's car moves 0.86 m a scan, 16 m over the run): a heading or pitch
drift of 0.025 degrees a scan leaves the run's end 0.07 m and 0.5 degrees off, AWD 0.06 m, the
3D registration's fitness 1.00: barely off. Doubling at each level, 0.4 degrees a scan leaves
it 1.15 m and 7.6 degrees off, fitness 0.6-0.7, the planes' f1 0.10-0.50: a clearly bad map.
0.8 would go past what the 3D consistency map can measure: its regions' ICP catches offsets of
about a metre (four 0.3 m voxels). A stretch
moves no point more than the run's end, so it takes a larger share to spoil the map as much:
1 % (0.16 m at the end, AWD 0.04 m, fitness 1.00) is barely off, 16 % (2.6 m, AWD 0.37 m,
fitness 0.79) clearly bad.

The vertical ladder's 3D consistency map is checked as :mod:`testkit.realdata.bends3d` checks
it: each region's expected dz from the true place of every point it holds. docs/validation.md's
section (``bench/validation/kitti_ladders.py``) and tests/realdata/test_kitti_ladders.py use it.
"""

from __future__ import annotations

import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import cache, lru_cache
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

from pcmapq.align.refine3d import last_reach
from pcmapq.align.regions3d import Consistency3D, regions_3d
from pcmapq.align.rigid3d import apply
from pcmapq.core.frames import Levelling
from pcmapq.core.transform import affine
from pcmapq.core.voxels import voxel_groups
from pcmapq.evaluation.inputs import load_pair, plan_points
from pcmapq.evaluation.scoring import structures_3d
from pcmapq.io.writers import write_cloud
from pcmapq.mapping import (
    ScanMap,
    build_map_from_poses,
    lidar_poses_from_camera,
    read_kitti_poses,
)
from pcmapq.mapping.reference import scans_for_poses
from pcmapq.match.structures import Structures3D
from pcmapq.metrics.distances import distances_3d
from pcmapq.metrics.map_gaussians import MapGaussians, map_gaussians
from pcmapq.results.result import Result
from pcmapq.settings import NoRefConfig, Settings
from testkit.kitti import curved, stretched, tr_00
from testkit.mapeval import mapeval_as_coded
from testkit.realdata.bends3d import (
    WITHIN_M,
    WITHIN_SHARE,
    placed_errors,
    region_dz,
    stretch_dz,
)
from testkit.runs import Run, timed_evaluate

#: Scans of the maps (the first ones of kitti00/velodyne).
SCANS = 20
#: The ladders: kind -> its five levels (degrees a scan; a share for scale).
LEVELS: dict[str, tuple[float, ...]] = {
    "heading": (0.025, 0.05, 0.1, 0.2, 0.4),
    "vertical": (0.025, 0.05, 0.1, 0.2, 0.4),
    "scale": (0.01, 0.02, 0.04, 0.08, 0.16),
}
#: As kitti_planes scores its ladder: the default settings but the no-reference figures.
SETTINGS = Settings(noref=NoRefConfig(enabled=False))
#: The scans' range in the maps (build_map_from_poses' default, as ``pcmapq map``), metres.
MAX_RANGE_M = 100.0
#: The maps' voxel (build_map_from_poses' default, as ``pcmapq map``), metres.
MAP_VOXEL_M = 0.1
#: The issue's bound on a figure's rank correlation with the level.
RHO = 0.9


def drifted(poses: np.ndarray, kind: str, level: float) -> np.ndarray:
    """LiDAR poses (K, 4, 4) drifting by ``kind`` ("heading", "vertical", "scale") at
    ``level`` (module docstring)."""
    if kind == "scale":
        return stretched(poses, level)
    return curved(poses, {"heading": "z", "vertical": "y"}[kind], level)


@lru_cache(maxsize=4)
def reference_poses(folder: Path) -> np.ndarray:
    """KITTI 00's LiDAR poses of the first scans (SCANS, 4, 4), in the first scan's frame."""
    return lidar_poses_from_camera(read_kitti_poses(folder / "poses.txt"), tr_00())[:SCANS]


@cache
def ladder_map(folder: Path, kind: str | None = None, level: float = 0.0) -> ScanMap:
    """The map of the first scans (points (N, 3) metres, each one's scan), as ``pcmapq map
    --poses`` builds it: at the reference poses (``kind`` None: the truth) or drifted; built
    once per process."""
    poses = reference_poses(folder)
    if kind is not None:
        poses = drifted(poses, kind, level)
    return build_map_from_poses(folder / "velodyne", poses, max_scans=SCANS,
                                max_range=MAX_RANGE_M, voxel=MAP_VOXEL_M)


def write_ladder_map(path: Path, built: ScanMap) -> None:
    """A ladder's map written as ``pcmapq map`` writes it: its points and their scans."""
    write_cloud(path, built.points, scan=built.scan)


@dataclass(frozen=True)
class Injected:
    """The drift at the run's end: how far the last scan's position is off (m), how far it
    is turned (deg) and its vertical error (m)."""

    offset_m: float
    turn_deg: float
    dz_m: float


def injected(folder: Path, kind: str, level: float) -> Injected:
    """The last scan's error under the drift."""
    truth = reference_poses(folder)
    drift = drifted(truth, kind, level)
    error = np.linalg.inv(truth[-1]) @ drift[-1]
    cos = np.clip((np.trace(error[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)
    return Injected(float(np.linalg.norm(drift[-1, :3, 3] - truth[-1, :3, 3])),
                    float(np.degrees(np.arccos(cos))), float(drift[-1, 2, 3] - truth[-1, 2, 3]))


@dataclass(frozen=True)
class Bend:
    """The vertical check of a 3D consistency map: the held region with the largest expected
    |dz| (its centroid x, y; the 5th and 95th percentiles of its points' vertical errors, m:
    how far apart the scans put its surfaces; its expected and reported dz, m), the largest
    reported dz (signed, m) and whether it is that region, and the median and largest
    |reported - expected| over the held regions (m); for stretches of the run, the far
    region's first and last scan and the expected dz of the region with the largest reported
    |dz| (m)."""

    far_at: tuple[float, float]
    spread_m: tuple[float, float]
    expected_m: float
    reported_m: float
    largest_m: float
    same_region: bool
    median_error_m: float
    max_error_m: float
    far_scans: tuple[int, int] | None = None
    largest_expected_m: float | None = None

    def within(self, injected_m: float) -> bool:
        """Reported within WITHIN_M plus WITHIN_SHARE of the injected offset of expected."""
        return abs(self.reported_m - self.expected_m) <= WITHIN_M + WITHIN_SHARE * abs(injected_m)


@dataclass(frozen=True)
class Rung:
    """One drifted map scored: its kind and level, the drift at the run's end, the
    evaluation, its 3D figures (:func:`figures_3d`), SCS as MapEval's code computes it on the
    map as the evaluation placed it (:func:`coded_scs`) and, for the vertical ladder, the check
    of its 3D consistency map."""

    kind: str
    level: float
    injected: Injected
    run: Run
    scs_as_coded: float | None
    bend: Bend | None

    @property
    def figures(self) -> dict[str, float | None]:
        return {**figures_3d(self.run.result), "scs_as_coded": self.scs_as_coded}

    def summary(self) -> dict:
        out = self.run.summary()
        out["figures_3d"] = self.figures
        out["transform_3d"] = self.run.result.registration_3d.transform.tolist()
        if self.bend is not None:
            out["bend"] = {k: list(v) if isinstance(v, tuple) else v
                           for k, v in self.bend.__dict__.items()}
        return out


#: The figures each ladder ranks by the level: name -> the way the issue asks it to move as
#: the map gets worse (1 up, -1 down, 0 one way or the other: SCS).
WAY = {"chamfer_3d_m": 1, "awd_m": 1, "scs": 0, "planes_f1": -1, "plane_lines_f1": -1,
       "largest_dz_m": 1, "largest_offset_m": 1}
#: Figures a ladder's drift is not asked to move: a horizontal drift moves no region up.
NOT_ASKED = {"heading": ("largest_dz_m",), "scale": ("largest_dz_m",), "vertical": ()}


def meets(name: str, value: float | None) -> bool:
    """Whether a figure's rank correlation with the level meets the issue's bound."""
    if value is None:
        return False
    return (abs(value) if WAY[name] == 0 else WAY[name] * value) >= RHO


def figures_3d(result: Result) -> dict[str, float | None]:
    """A result's figures of two 3D clouds (:func:`figures_of`)."""
    return figures_of(result.distances_3d.chamfer_m, result.map_3d, result.structures,
                      result.consistency_3d)


def figures_of(chamfer_m: float, gaussians: MapGaussians | None,
               structures: Structures3D | None,
               consistency: Consistency3D | None) -> dict[str, float | None]:
    """The figures of two 3D clouds the ladders rank: the Chamfer distance in 3D (m), AWD (m),
    SCS, the planes' and plane lines' f1, the 3D consistency map's largest |dz| and largest
    offset over its held regions (m), and its held and all regions."""
    c, s = consistency, structures
    dz, off = (None, None) if c is None else (c.largest_dz(), c.largest())
    return {
        "chamfer_3d_m": chamfer_m,
        "awd_m": None if gaussians is None else gaussians.awd_m,
        "scs": None if gaussians is None else gaussians.scs,
        "planes_f1": None if s is None else s.detectors["planes"].matching.f1,
        "plane_lines_f1": None if s is None else s.detectors["plane_lines"].matching.f1,
        "largest_dz_m": None if dz is None else float(abs(c.offset[dz, 2])),
        "largest_offset_m": None if off is None else float(c.offset_m[off]),
        "held": None if c is None else int(c.held.sum()),
        "regions": None if c is None else len(c.points),
    }


def direct_figures(folder: Path, kind: str, level: float, transform: np.ndarray
                   ) -> tuple[dict[str, float | None], Bend | None]:
    """The figures of :func:`figures_of` computed as the evaluation computes them once its 3D
    registration has placed the map at ``transform`` (4x4 map -> truth), without the
    registration and the 2D pipeline: both maps written and read as ``pcmapq eval`` reads
    them, each figure by the function its scoring calls with SETTINGS, on as many threads; and
    the vertical ladder's check of its 3D consistency map (:func:`bend`)."""
    settings, m3 = SETTINGS, SETTINGS.map_3d
    with tempfile.TemporaryDirectory(prefix="pcmapq_ladders3d_") as tmp:
        truth_path, map_path = Path(tmp) / "truth.ply", Path(tmp) / "map.ply"
        write_ladder_map(truth_path, ladder_map(folder))
        write_ladder_map(map_path, ladder_map(folder, kind, level))
        source, truth = load_pair(map_path, truth_path, settings)
    level_of = plan_points(truth, settings)[1]
    placed, target = apply(np.asarray(transform, dtype=np.float64), source.points), truth.points
    with ThreadPoolExecutor(3) as pool:
        chamfer = pool.submit(distances_3d, placed, target, settings.raster.cloud_resolution,
                              settings.distances.taus)
        regions = pool.submit(regions_3d, placed, target, tile_m=m3.tile,
                              voxel=settings.alignment.voxel_3d,
                              level=None if level_of is None else level_of.rotation,
                              scan=source.scan)
        gaussians = pool.submit(map_gaussians, placed, target, m3.voxel, m3.min_points,
                                m3.radius)
        structures = pool.submit(structures_3d, target, placed, settings.structures,
                                 last_reach(settings.alignment.voxel_3d))
        figures = figures_of(chamfer.result().chamfer_m, gaussians.result(),
                             structures.result(), regions.result())
    figures["scs_as_coded"] = coded_scs(placed, target)
    return figures, (bend(folder, kind, level, regions.result(), transform, level_of)
                     if kind == "vertical" else None)


def coded_scs(placed: np.ndarray, truth: np.ndarray) -> float | None:
    """SCS of the map ``placed`` (N, 3, in the truth's frame) against ``truth`` (M, 3) as
    MapEval's code computes it (:func:`testkit.mapeval.mapeval_as_coded`, its defaults: 3 m
    voxels, 100 points, a neighbourhood of 5 voxels), rounded to 1e-6 as results are saved."""
    scs = mapeval_as_coded(np.asarray(placed, dtype=np.float64),
                           np.asarray(truth, dtype=np.float64))[1]
    return None if scs is None else round(scs, 6)


def rho(levels: list[float], values: list[float | None]) -> float | None:
    """Spearman's rank correlation of a figure with the level; None when a level lacks it."""
    if any(v is None for v in values):
        return None
    # rounded: a rank correlation of a few levels is a multiple of a simple fraction
    return round(float(spearmanr(levels, values)[0]), 6)


@lru_cache(maxsize=4)
def scans(folder: Path) -> tuple[np.ndarray, ...]:
    """The first scans' points (each (N, 3) metres, the scanner's frame) within the maps'
    range: the points each map places (read once per process)."""
    return tuple(p[np.linalg.norm(p, axis=1) <= MAX_RANGE_M]
                 for p, _ in scans_for_poses(folder / "velodyne", SCANS, max_scans=SCANS))


def bend(folder: Path, kind: str, level: float, consistency: Consistency3D | None,
         transform: np.ndarray, level_of: Levelling | None) -> Bend:
    """The check of a drifted map's 3D consistency map (the map placed by ``transform``, 4x4
    map -> truth; ``level_of``: the truth's levelling) against each region's expected dz, the
    mean error of its points (:func:`testkit.realdata.bends3d.region_dz`)."""
    c = consistency
    if c is None or not c.held.any():
        raise RuntimeError(f"{kind} {level}: no held region of a 3D consistency map")
    truth, points = reference_poses(folder), list(scans(folder))
    drift = drifted(truth, kind, level)
    placed, error = placed_errors(points, truth, drift, transform,
                                  None if level_of is None else level_of.rotation)
    if c.scans is None:  # tiles: a point is in the region whose tile holds it
        expected = region_dz(placed, error[:, 2], c.centre, c.tile_m, c.voxel_m)
        point_of = np.floor(placed[:, :2] / c.tile_m).astype(np.int64)
        region_of = np.floor(c.centre[:, :2] / c.tile_m).astype(np.int64)
    else:  # stretches: in the one holding its scan
        point_of = point_stretches(points, drift, c.stretch)[:, None]
        region_of = c.scans[:, :1] // c.stretch
        expected = stretch_dz(placed, error[:, 2], point_of[:, 0], region_of[:, 0], c.voxel_m)
    far = int(np.flatnonzero(c.held)[np.argmax(np.abs(expected[c.held]))])
    largest = c.largest_dz()
    gap = np.abs(c.offset[c.held, 2] - expected[c.held])
    spread = np.percentile(error[np.all(point_of == region_of[far], axis=1), 2], [5, 95])
    return Bend(tuple(np.round(c.centre[far, :2], 1).tolist()),
                tuple(np.round(spread, 6).tolist()), round(float(expected[far]), 6),
                float(c.offset[far, 2]), float(c.offset[largest, 2]), largest == far,
                round(float(np.median(gap)), 6), round(float(gap.max()), 6),
                None if c.scans is None else tuple(c.scans[far].tolist()),
                None if c.scans is None else round(float(expected[largest]), 6))


def point_stretches(points: list[np.ndarray], poses: np.ndarray, stretch: int) -> np.ndarray:
    """The stretch of the run (N,) each of the scans' ``points`` (scanner frame) falls in, as
    the map placed at ``poses`` records it: its map voxel's mean scan index (MAP_VOXEL_M, the
    map's frame), divided by the ``stretch`` scans a stretch holds."""
    in_map = np.vstack([affine(p, pose) for p, pose in zip(points, poses, strict=True)])
    scan_of = np.repeat(np.arange(len(points)), [len(p) for p in points])
    _, voxel_of = voxel_groups(in_map, MAP_VOXEL_M)
    mean = np.bincount(voxel_of, scan_of) / np.bincount(voxel_of)
    return np.floor(mean[voxel_of] / stretch).astype(np.int64)


def measure(folder: Path, kind: str, level: float) -> Rung:
    """The drifted map scored against the truth as ``pcmapq eval map.ply truth.ply`` with
    SETTINGS scores them; the vertical ladder's consistency map checked."""
    with tempfile.TemporaryDirectory(prefix="pcmapq_ladders3d_") as tmp:
        truth, cloud = Path(tmp) / "truth.ply", Path(tmp) / "map.ply"
        write_ladder_map(truth, ladder_map(folder))
        write_ladder_map(cloud, ladder_map(folder, kind, level))
        run = timed_evaluate(cloud, truth, SETTINGS)
        source, target = load_pair(cloud, truth, SETTINGS)
    r = run.result
    placed = apply(np.asarray(r.registration_3d.transform, dtype=np.float64), source.points)
    return Rung(kind, level, injected(folder, kind, level), run,
                coded_scs(placed, target.points),
                bend(folder, kind, level, r.consistency_3d, r.registration_3d.transform,
                     r.frames.truth_levelling) if kind == "vertical" else None)
