"""Where a 3D map bends: each region of a 3D cloud map, already placed on the truth cloud by the
global 3D registration, registered again on its own to the truth in six degrees of freedom. A
consistent map needs no region to move; a map that sinks, tilts or drifts along the run needs its
regions moved by offsets that grow where it bends, and the vertical part of those offsets (dz)
shows what a plan cannot.

Regions are square tiles of the truth's ground plane, or, for a map that carries the scan each
point came from (a map ``pcmapq map`` built, :mod:`pcmapq.mapping.scan_map`), stretches of the
run (:mod:`pcmapq.align.stretches`): consecutive scans, their points wherever they lie. A drift
builds up along the run, so a stretch holds points placed with nearly one error, where a tile
of a long-range scanner's map holds points of every scan that saw it, each put elsewhere.
Each region's own map points (at ``voxel``) are registered by small_gicp's point-to-plane ICP
(as :mod:`pcmapq.align.plane_icp` computes it: its loops leave Python's lock to the
evaluation's other threads), seeded at identity (the global pose), on one thread, coarse to
fine: a tile against the truth's points within the tile grown by the widest pairing distance
on every side (their normals and KD-tree small_gicp's); a stretch, whose points reach as far
as its scans do and overlap the other stretches', against all the truth's points, their
normals and KD-tree made once for every stretch.
Frame: the truth cloud levelled as its plan is (x, y the truth's plan, the 2D consistency map's
frame; z up), metres and degrees. ``offset`` is the map's error there: where the map (as the
global registration placed it) has the region's centroid, from where the region fits the truth
on its own (a map that sank has dz < 0); roll, pitch and yaw are the region's turn about x, y
and z from its fit, the same way round.

A region is held when the ICP's information pins all six of its degrees of freedom and it fits:
the 6 x 6 Hessian of the point-to-plane cost at the fit, per pair and with its turns taken as
the movement of a point at the region's half side (a tile's; a stretch's points' wider extent
in the plan), has its smallest eigenvalue at least MIN_INFORMATION (a ground alone leaves x, y
and yaw free; a straight facade on it, x), and at least MIN_FIT of the region's points lie
within the tolerance of a truth point once it is registered."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import small_gicp
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from pcmapq.align.plane_icp import Nearest, plane_icp, prepared
from pcmapq.align.stretches import stretches
from pcmapq.core.transform import affine
from pcmapq.core.voxels import voxel_centroids

__all__ = ["Consistency3D", "regions_3d"]

#: A tile's side by default, metres: a 20-scan KITTI stretch (about 16 m) spans a few tiles.
TILE_M = 8.0
#: Regions at most this many tiles across the map's larger side (a larger map gets larger
#: tiles: the cost stays that of a map of this many tiles).
MAX_TILES = 32
#: A tile or stretch holding fewer map points than this (at the working voxel) is no region.
MIN_POINTS = 200
#: ICP stages: the largest pairing distance of each, in units of the working voxel (wide first:
#: at the 0.3 m default, offsets of up to about a metre are caught).
STAGES = (4.0, 2.0, 1.0)
#: Iterations per stage, at most; a stage stops when a step turns less than SETTLED radians and
#: moves less than SETTLED metres.
ITERATIONS = 30
SETTLED = 1e-4
#: Neighbours of a truth point that fit its normal.
NORMAL_NEIGHBOURS = 20
#: A region is held when the smallest eigenvalue of its normalised information (module
#: docstring) is at least this: every direction has at least this share of a pair's pull.
MIN_INFORMATION = 0.01
#: ... and at least this share of its points lie within the tolerance of the truth once fitted.
MIN_FIT = 0.5


@dataclass(frozen=True)
class Consistency3D:
    """The regions of one registered 3D map, as arrays (K regions), in the truth's levelled
    frame (module docstring), metres and degrees.

    tile_m: a tile's side (regions cut by scans: None). voxel_m: the working voxel the points
    are taken at. tolerance_m: the distance within which a point fits a truth point. centre:
    (K, 3) centroid of each region's map points. offset: (K, 3) dx, dy, dz, the map's error:
    its region from where the region fits the truth. angles_deg: (K, 3) roll, pitch, yaw,
    likewise. points: (K,) the region's map points. fit_before, fit_after: (K,) share of them
    within the tolerance of a truth point at the global pose and once the region is registered
    on its own. held: (K,) whether its fit is pinned in every direction and fits (module
    docstring). scans: for regions cut by scans, (K, 2) int the first and last scan of each
    stretch; None for tiles. stretch: the scans a stretch holds (0 for tiles)."""

    tile_m: float | None
    voxel_m: float
    tolerance_m: float
    centre: np.ndarray
    offset: np.ndarray
    angles_deg: np.ndarray
    points: np.ndarray
    fit_before: np.ndarray
    fit_after: np.ndarray
    held: np.ndarray
    scans: np.ndarray | None = None
    stretch: int = 0

    @classmethod
    def empty(cls, tile_m: float | None, voxel_m: float, tolerance_m: float,
              stretch: int = 0) -> Consistency3D:
        """A consistency map with no region."""
        none = np.zeros((0, 3))
        return cls(tile_m, voxel_m, tolerance_m, none, none, none, np.zeros(0, int),
                   np.zeros(0), np.zeros(0), np.zeros(0, bool),
                   np.zeros((0, 2), int) if stretch else None, stretch)

    @property
    def offset_m(self) -> np.ndarray:
        """(K,) length of each region's offset, metres."""
        return np.linalg.norm(self.offset, axis=1)

    def largest(self) -> int | None:
        """Index of the held region with the longest offset; None without one."""
        return self._most(self.offset_m)

    def largest_dz(self) -> int | None:
        """Index of the held region with the largest vertical offset |dz|; None without one."""
        return self._most(np.abs(self.offset[:, 2]))

    def cut(self) -> str:
        """How the map is cut into regions, in words: ``8 m tiles``, ``stretches of 4 scans``."""
        return (f"{self.tile_m:g} m tiles" if self.scans is None else
                f"stretches of {self.stretch} scans")

    def scan_span(self, k: int) -> str:
        """Region ``k``'s scans in words (``scans 4-7``); "" for a tile."""
        return "" if self.scans is None else f"scans {self.scans[k, 0]}-{self.scans[k, 1]}"

    def _most(self, values: np.ndarray) -> int | None:
        held = np.flatnonzero(self.held)
        return None if len(held) == 0 else int(held[np.argmax(values[held])])


def levelled(points: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
    """Points (N, 3) turned by the truth's levelling ``rotation`` (3x3; None: as they are)."""
    return points if rotation is None else points @ np.asarray(rotation).T


def _in_box(sorted_xy: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Indices into ``sorted_xy`` (N, 2, sorted by x) of the points with lo <= xy < hi."""
    start, stop = np.searchsorted(sorted_xy[:, 0], [lo[0], hi[0]])
    y = sorted_xy[start:stop, 1]
    return start + np.flatnonzero((y >= lo[1]) & (y < hi[1]))


def _register(nearest: Nearest, normals: np.ndarray, voxel: float
              ) -> tuple[np.ndarray, np.ndarray]:
    """Point-to-plane ICP of ``nearest``'s source onto its target (both centred on the
    source's centroid; ``normals`` the target's), from identity, coarse to fine: the 4x4 move
    and the last stage's 6 x 6 Hessian (turns about x, y, z, then x, y, z translations) per
    pair."""
    move, hessian = np.eye(4), np.zeros((6, 6))
    for units in STAGES:
        fit = plane_icp(nearest, normals, move, units * voxel, ITERATIONS, SETTLED, SETTLED)
        move, hessian = fit.transform, fit.hessian / max(fit.inliers, 1)
    return move, hessian


def _pinned(hessian: np.ndarray, half_side: float) -> float:
    """The smallest eigenvalue of ``hessian`` (per pair; turns first) with its turns scaled to
    the movement of a point ``half_side`` metres from the centre: 1 for a pull as strong as
    one pair's in every direction, 0 for a direction nothing holds."""
    scale = np.array([half_side] * 3 + [1.0] * 3)
    return float(np.linalg.eigvalsh(hessian / np.outer(scale, scale))[0])


class _Truth:
    """The truth's points (M, 3, levelled, at the working voxel) as each region needs them:
    sorted by x for a tile's window, a KD-tree for the fit, and for stretches, whose windows
    overlap, small_gicp's KD-tree and normals of all of them, made once."""

    def __init__(self, truth: np.ndarray) -> None:
        self.points = truth
        self.sorted = truth[np.argsort(truth[:, 0], kind="stable")]
        self.tree = cKDTree(truth)
        self._whole: tuple[small_gicp.KdTree, np.ndarray] | None = None

    def whole(self) -> tuple[small_gicp.KdTree, np.ndarray]:
        """small_gicp's KD-tree of all the truth's points and their normals (M, 3)."""
        if self._whole is None:
            cloud = small_gicp.PointCloud(self.points)
            tree = small_gicp.KdTree(cloud, num_threads=1)
            small_gicp.estimate_normals(cloud, tree, num_neighbors=NORMAL_NEIGHBOURS,
                                        num_threads=1)
            self._whole = tree, np.ascontiguousarray(cloud.normals()[:, :3])
        return self._whole


def _row(own: np.ndarray, truth: _Truth, lo: np.ndarray, hi: np.ndarray, half_side: float,
         voxel: float, whole: bool = False) -> tuple | None:
    """The row of one region, its map points ``own`` (N, 3, levelled truth frame, at ``voxel``
    metres) in the box ``lo``-``hi`` (x, y, metres), registered on its own to the truth's
    points in that box grown by the widest pairing distance (``whole``: to all of them, their
    normals found once): its centroid, offset, turn (degrees), points, fit before and after,
    and whether it is held (its turns scaled by ``half_side`` metres); None when the truth has
    too few points there."""
    tolerance, margin = voxel / 2, STAGES[0] * voxel
    near = _in_box(truth.sorted[:, :2], lo - margin, hi + margin)
    if len(near) < NORMAL_NEIGHBOURS:
        return None
    centre = own.mean(axis=0)
    if whole:
        tree, normals = truth.whole()
        nearest = Nearest(own - centre, truth.points - centre, tree, offset=centre)
    else:
        nearest, normals = prepared(own - centre, truth.sorted[near] - centre,
                                    NORMAL_NEIGHBOURS)
    move, hessian = _register(nearest, normals, voxel)
    before = truth.tree.query(own, distance_upper_bound=tolerance, workers=1)[0]
    fitted = affine(own - centre, move) + centre
    after = truth.tree.query(fitted, distance_upper_bound=tolerance, workers=1)[0]
    fit_after = float(np.isfinite(after).mean())
    # the map's error: its region's centroid from where the fit puts it, and its turn
    angles = Rotation.from_matrix(move[:3, :3].T).as_euler("xyz", degrees=True)
    held = _pinned(hessian, half_side) >= MIN_INFORMATION and fit_after >= MIN_FIT
    return (*centre, *-move[:3, 3], *angles, len(own), float(np.isfinite(before).mean()),
            fit_after, held)


def _tile_rows(placed: np.ndarray, truth: _Truth, tile_m: float, voxel: float) -> list[tuple]:
    """One row per region of ``placed`` (N, 3, levelled truth frame, at ``voxel`` metres) in
    tiles of ``tile_m`` metres (:func:`_row`)."""
    keys = np.floor(placed[:, :2] / tile_m).astype(np.int64)
    tiles, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    order = np.argsort(inverse.ravel(), kind="stable")
    bounds_at = np.concatenate([[0], np.cumsum(counts)])
    rows = []
    for k in np.flatnonzero(counts >= MIN_POINTS):
        row = _row(placed[order[bounds_at[k]:bounds_at[k + 1]]], truth, tiles[k] * tile_m,
                   (tiles[k] + 1) * tile_m, tile_m / 2, voxel)
        if row is not None:
            rows.append(row)
    return rows


def _stretch_rows(map_xyz: np.ndarray, scan: np.ndarray, stretch: int | None, truth: _Truth,
                  voxel: float, level: np.ndarray | None
                  ) -> tuple[list[tuple], list[tuple[int, int]], int]:
    """One row per stretch of ``stretch`` scans (None: :func:`~pcmapq.align.stretches.
    stretch_scans`) of the run of the map ``map_xyz`` (N, 3, truth frame; ``scan`` (N,) each
    point's scan): each stretch's points at ``voxel`` metres, levelled by ``level``,
    registered on their own (:func:`_row`); with each row's first and last scan, and the scans
    a stretch holds (ValueError: see :func:`~pcmapq.align.stretches.run_stretches`)."""
    stretch, each = stretches(scan, stretch)
    rows, spans = [], []
    for index, span in each:
        own = levelled(voxel_centroids(np.asarray(map_xyz)[index], voxel), level)
        if len(own) < MIN_POINTS:
            continue
        lo, hi = own[:, :2].min(axis=0), own[:, :2].max(axis=0)
        row = _row(own, truth, lo, hi, float(np.max(hi - lo)) / 2, voxel, whole=True)
        if row is not None:
            rows.append(row)
            spans.append(span)
    return rows, spans, stretch


def regions_3d(map_xyz: np.ndarray, truth_xyz: np.ndarray, *, tile_m: float = TILE_M,
               voxel: float = 0.3, level: np.ndarray | None = None,
               scan: np.ndarray | None = None, stretch: int | None = None) -> Consistency3D:
    """The regions of the map ``map_xyz`` (N, 3, already in the truth cloud's frame), each
    registered on its own to ``truth_xyz`` (M, 3), metres.

    scan: (N,) each map point's scan (:mod:`pcmapq.mapping.scan_map`): regions are then
    stretches of the run of ``stretch`` scans each (:mod:`pcmapq.align.stretches`; 0: tiles);
    None: tiles.
    tile_m: a tile's side, metres (grown so that the map spans at most MAX_TILES tiles).
    voxel: both clouds are taken at this voxel (centroids), metres; the pairing distances
    scale with it (STAGES) and a point fits within half of it. level: the truth's levelling
    rotation (3x3), applied to both first, so that tiles lie on its ground and dz is
    vertical; None: the truth frame as it is. Deterministic."""
    tolerance = voxel / 2
    # the centroids of a large cloud are streamed (any float type, a file mapped into memory
    # read in chunks): no copy of all its points is made
    truth = levelled(voxel_centroids(np.asarray(truth_xyz), voxel), level)
    spans = None
    if scan is not None and stretch != 0 and len(map_xyz) and len(truth) >= NORMAL_NEIGHBOURS:
        tile = None
        rows, spans, stretch = _stretch_rows(map_xyz, scan, stretch, _Truth(truth), voxel,
                                             level)
    else:
        placed = levelled(voxel_centroids(np.asarray(map_xyz), voxel), level)
        if len(placed) == 0 or len(truth) < NORMAL_NEIGHBOURS:
            return Consistency3D.empty(tile_m, voxel, tolerance)
        tile = max(tile_m, float(np.ptp(placed[:, :2], axis=0).max()) / MAX_TILES)
        rows, stretch = _tile_rows(placed, _Truth(truth), tile, voxel), 0
    if not rows:
        return Consistency3D.empty(tile, voxel, tolerance, stretch)
    # to the micrometre (and 1e-6 of a share or degree), as results are saved: the figures
    # made from them are then the same read back from JSON
    table = np.round(np.array(rows, dtype=np.float64), 6) + 0.0
    return Consistency3D(tile, voxel, tolerance, table[:, :3], table[:, 3:6], table[:, 6:9],
                         table[:, 9].astype(int), table[:, 10], table[:, 11], table[:, 12] > 0,
                         None if spans is None else np.array(spans, dtype=int).reshape(-1, 2),
                         stretch)
