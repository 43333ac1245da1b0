"""Cloud-to-cloud style distance metrics on the truth's grid: accuracy, completeness, Chamfer
distance and precision / recall / F-score at distance thresholds (definitions in
docs/metrics.md). Exact Euclidean distance transforms (:func:`pcmapq.core.morphology.distance_to`);
metres."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import distance_to
from pcmapq.core.stats import Stats
from pcmapq.metrics.defaults import DEFAULT_TAUS


@dataclass(frozen=True)
class FScore:
    """Precision (map cells within tau of the truth), recall (covered truth cells within tau of
    the map) and their harmonic mean, at threshold ``tau_m`` metres."""

    tau_m: float
    precision: float
    recall: float
    f: float


@dataclass(frozen=True)
class Distances:
    """Wall distances, metres; ``basis``: what they are computed on, in words."""

    accuracy: Stats      # map -> truth
    completeness: Stats  # truth (inside the footprint) -> map
    chamfer_m: float | None      # mean of the two means
    fscores: tuple[FScore, ...]
    basis: str = ""


@dataclass(frozen=True)
class DistanceField:
    """Each cell's distance to the nearest true cell of a raster (inf everywhere when it has
    none), kept in cells as the transform gives them (float32) and read in metres:
    ``field[where]`` is the float64 metres of the cells ``where`` selects (any NumPy index),
    so that a distance of whole cells compares exactly with a threshold in metres. The same
    values as a float64 field of metres, in half its memory (4 bytes a cell)."""

    cells: np.ndarray
    resolution: float

    def __getitem__(self, where: object) -> np.ndarray:
        return np.multiply(self.cells[where], self.resolution, dtype=np.float64)


def nearest_distance(target: np.ndarray, grid: MetricGrid) -> DistanceField:
    """Distance in metres from every cell to the nearest true cell of ``target`` (inf if none),
    on ``grid`` (the transform is float32 in cells, exact up to its rounding)."""
    return DistanceField(distance_to(target), grid.resolution)


def distances(truth_occ: np.ndarray, map_occ: np.ndarray, footprint: np.ndarray,
              grid: MetricGrid, taus: tuple[float, ...] = DEFAULT_TAUS,
              to_map: DistanceField | None = None,
              to_truth: DistanceField | None = None, band: str = "") -> Distances:
    """Distance metrics between the occupied cells of the aligned map and of the truth.

    truth_occ, map_occ, footprint: (rows, cols) bool on ``grid``. Completeness and recall only
    count the truth cells inside ``footprint`` (the area the map observed). to_map, to_truth:
    the map's and the truth's :func:`nearest_distance` fields, when the caller has them.
    band: how a 3D cloud's cells were made, for the basis (" (a 3D cloud: ...)").
    """
    to_map = nearest_distance(map_occ, grid) if to_map is None else to_map
    to_truth = nearest_distance(truth_occ, grid) if to_truth is None else to_truth
    acc = to_truth[map_occ]
    comp = to_map[truth_occ & footprint]
    return _summary(acc, comp, taus, cells_basis(grid.resolution, band))


def cells_basis(resolution: float, band: str = "") -> str:
    """What :func:`distances` computes on, in words."""
    return (f"in the plan: every occupied cell of the map on the truth's {resolution:g} m grid"
            f"{band} to the nearest truth cell (accuracy, precision); every truth cell inside "
            "the footprint to the nearest map cell (completeness, recall)")


def accuracy_2d(map_occ: np.ndarray, grid: MetricGrid,
                to_truth: DistanceField) -> tuple[np.ndarray, np.ndarray]:
    """The points and distances :func:`distances`' accuracy is computed on: the centres (N, 2)
    of the map's occupied cells on ``grid`` and each one's distance to the truth (N,), metres
    (``to_truth``: the truth's :func:`nearest_distance` field)."""
    return grid.cell_centres(map_occ), to_truth[map_occ]


def _summary(acc: np.ndarray, comp: np.ndarray, taus: tuple[float, ...],
             basis: str) -> Distances:
    """Metrics from the map->truth (``acc``) and truth->map (``comp``) distances, metres."""
    a, c = Stats.of(acc), Stats.of(comp)
    chamfer = None if a.mean is None or c.mean is None else 0.5 * (a.mean + c.mean)
    scores = []
    for tau in taus:
        p = float(np.mean(acc <= tau)) if len(acc) else 0.0
        r = float(np.mean(comp <= tau)) if len(comp) else 0.0
        scores.append(FScore(tau, p, r, 2 * p * r / (p + r) if p + r > 0 else 0.0))
    return Distances(a, c, chamfer, tuple(scores), basis)


def distances_3d(map_xyz: np.ndarray, truth_xyz: np.ndarray, voxel: float = 0.05,
                 taus: tuple[float, ...] = DEFAULT_TAUS) -> Distances:
    """The same metrics between two aligned 3D clouds (N, 3) and (M, 3), metres, in the truth
    frame, as MapEval and Tanks-and-Temples compute them: nearest-neighbour distances between
    the clouds voxel-downsampled to ``voxel`` metres (centroids, :func:`voxel_centroids`).

    The exact nearest neighbours come from Open3D's ``compute_point_cloud_distance`` (a KD-tree,
    every core), one call per direction: the distances SciPy's ``cKDTree`` gives, in about
    two thirds of its time (``bench/bench_clouds.py``). Each cloud's centroids are handed to
    Open3D once (a cloud of more than STRIPE_POINTS points reduced in stripes of x)."""
    from pcmapq.core.voxels import stripe_points, voxel_centroids

    basis = (f"in 3D: the map's and the truth's points voxel-downsampled to {voxel:g} m "
             "(centroids), each to the nearest of the other's")
    m, t = (voxel_centroids(c, voxel, stripe_points=stripe_points(len(c)))
            for c in (map_xyz, truth_xyz))
    if len(m) == 0 or len(t) == 0:
        return _summary(np.full(len(m), np.inf), np.full(len(t), np.inf), taus, basis)
    clouds = [_open3d_cloud(m), _open3d_cloud(t)]
    del m, t  # Open3D holds its own copies
    acc = np.asarray(clouds[0].compute_point_cloud_distance(clouds[1]))
    comp = np.asarray(clouds[1].compute_point_cloud_distance(clouds[0]))
    return _summary(acc, comp, taus, basis)


def accuracy_3d(map_xyz: np.ndarray, truth_xyz: np.ndarray,
                voxel: float) -> tuple[np.ndarray, np.ndarray]:
    """The points and distances :func:`distances_3d`' accuracy is computed on: the map's voxel
    centroids (N, 3) and each one's distance to the nearest truth voxel centroid (N,),
    metres."""
    from pcmapq.core.voxels import voxel_centroids

    m, t = voxel_centroids(map_xyz, voxel), voxel_centroids(truth_xyz, voxel)
    return m, (_nearest_3d(m, t) if len(t) else np.full(len(m), np.inf))


def _nearest_3d(points: np.ndarray, other: np.ndarray) -> np.ndarray:
    """Each point's (N, 3) distance to the nearest of ``other`` (M, 3), metres (Open3D)."""
    clouds = [_open3d_cloud(c) for c in (points, other)]
    return np.asarray(clouds[0].compute_point_cloud_distance(clouds[1]))


def _open3d_cloud(points: np.ndarray):  # -> o3d.geometry.PointCloud (Open3D loaded here)
    """An Open3D cloud of ``points`` (N, 3), metres (a copy)."""
    import open3d as o3d

    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
