"""2D alignment of a map to the truth with no initial guess: a global raster search
(:mod:`~pcmapq.align.coarse`), then ICP from its best candidates. ``Alignment.transform`` takes
map-frame points to the truth frame, ``p_truth = s * R(yaw) * p_map + t``.

Rigid and similarity alignment run the same refinement
(:func:`~pcmapq.align.finalists.refine_best`): a rough ICP stage from every candidate of the
search (or from ``init``), the best ``finalists`` of those by fitness through the fine stages,
and the best of these by fitness, then RMSE. Point-to-line finishes it: each finalist's fine
stages with the scale free, the winner alone when rigid."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.align.coarse import (
    Search,
    auto_resolution,
    coarse_search,
    distinctiveness,
    similarity_resolution,
    similarity_search,
)
from pcmapq.align.finalists import refine_best, same_pose, support
from pcmapq.align.free_space import FreeSpace
from pcmapq.align.params import AlignParams
from pcmapq.align.point_to_line import LineTarget, refine_point_to_line
from pcmapq.align.point_to_point import DEFAULT_SCHEDULE, IcpTarget, refine_point_to_point
from pcmapq.align.pyramid import descend
from pcmapq.align.similarity_icp import SimilarityTarget, refine_similarity, similarity_schedule
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import evenly, thinned, voxel_centroids

#: The truth keeps this many times the map's ``max_points``: a sparse target would put map points
#: on its walls farther than the tolerance from its nearest point.
TRUTH_POINTS = 10
#: A thinned map (more than ``max_points`` voxels) runs its point-to-point ICP stages on this many
#: of its points, evenly spread, against the truth downsampled to THINNED_TRUTH_VOXEL metres for
#: every stage: the pose of a few thousand wall points is as sure, and each of the many ICP
#: iterations costs in proportion to the map's points. The point-to-line finish, fitness and
#: RMSE still use every thinned map point and truth point.
ICP_POINTS = 5_000
THINNED_TRUTH_VOXEL = 0.4

@dataclass(frozen=True)
class Alignment:
    """The result of :func:`align`.

    transform: map frame -> truth frame. fitness: share of (voxel-downsampled) map points within
    ``tolerance_m`` of a truth point after alignment, [0, 1]. rmse_m: RMSE of those inlier
    distances, metres. method: "coarse+icp", "similarity+icp" (global search over scale too),
    "init+icp", "init" or "none"; after a 3D registration (:mod:`pcmapq.evaluation.placing`)
    "3d", or "3d+init" when it started where ``--init-3d`` said. distinctiveness: how far
    the final pose's score in the global search stands above the best score elsewhere, [0, 1]
    (see :func:`~pcmapq.align.coarse.distinctiveness`); None when there was no global search.
    contradiction: share of the map's free cells (those farther than
    :data:`~pcmapq.align.free_space.CLEAR_M` from its walls) on the truth's known cells that
    the pose puts on a truth wall or solid block, [0, 1]; None for a map without free space.
    free_on_truth: share of those free cells that the pose puts on the truth's known cells,
    [0, 1]; None for a map without free space.
    poses: the two best distinct poses refined from the global search's candidates (the
    finalists, then the other candidates after the rough ICP stage), best first, with their
    support (:func:`~pcmapq.align.finalists.support`: the fitness, lowered by what the
    map's free space costs the pose); empty when there was no search.
    """

    transform: Similarity2D
    fitness: float
    rmse_m: float
    tolerance_m: float
    method: str
    distinctiveness: float | None = None
    contradiction: float | None = None
    free_on_truth: float | None = None
    poses: tuple[tuple[Similarity2D, float], ...] = ()


def _score_tree(map_xy: np.ndarray, tree: cKDTree, tf: Similarity2D,
                tolerance: float) -> tuple[float, float]:
    """(fitness, rmse in metres) of the map (N, 2, map frame) against a truth KD-tree."""
    if len(map_xy) == 0:
        return 0.0, 0.0
    # one thread: SciPy starts and joins threads for each query, which costs more than the
    # query of a thinned map saves, and a tracked run's steps keep the cores busy
    # (docs/benchmarks.md, "Quality over a run")
    dist, _ = tree.query(tf.apply(map_xy), distance_upper_bound=tolerance, workers=1)
    inliers = dist[np.isfinite(dist)]
    rmse = float(np.sqrt(np.mean(inliers**2))) if len(inliers) else 0.0
    return len(inliers) / len(map_xy), rmse


def score(map_xy: np.ndarray, truth_xy: np.ndarray, tf: Similarity2D,
          tolerance: float = 0.2) -> tuple[float, float]:
    """(fitness, rmse): the share of map points (N, 2, metres, map frame) that ``tf`` puts within
    ``tolerance`` metres of a truth point (M, 2, metres, truth frame), and the RMSE in metres of
    those inlier distances (0 when there are none)."""
    tree = cKDTree(np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2))
    return _score_tree(np.asarray(map_xy, dtype=np.float64).reshape(-1, 2), tree, tf, tolerance)


class RigidTarget:
    """The truth prepared once for the rigid alignment of many maps (``pcmapq track``'s
    steps): its points thinned as :func:`align` thins them, their KD-tree, the point-to-line
    target (whose line normals, each depending on its point alone, are kept as they are
    computed) and the point-to-point clouds by voxel. Aligning with it gives what aligning
    with the truth's points gives, from several threads at once (its caches hold what any
    thread would compute)."""

    def __init__(self, truth_xy: np.ndarray, params: AlignParams = AlignParams()) -> None:
        """truth_xy: (M, 2) metres, truth frame; params: those of the alignments to come."""
        self.voxel, self.max_points = params.voxel, params.max_points
        self.points, _ = thinned(np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2),
                                  params.voxel, TRUTH_POINTS * params.max_points)
        self.tree = cKDTree(self.points) if len(self.points) else None
        self.lines = LineTarget(self.points, self.tree) if len(self.points) else None
        self.clouds: dict = {}

    def fits(self, params: AlignParams) -> bool:
        """Whether this target serves alignments with ``params``."""
        return (params.voxel, params.max_points) == (self.voxel, self.max_points)


def align(map_xy: np.ndarray, truth_xy: np.ndarray, params: AlignParams = AlignParams(), *,
          init: Similarity2D | None = None, refine: bool = True,
          scale: bool = False, target: RigidTarget | None = None,
          free: FreeSpace | None = None) -> Alignment:
    """Align a map to the truth with no initial guess needed; never fails on a bad match (an
    empty map or truth gives fitness 0).

    map_xy: (N, 2) metres, map frame (map units with ``scale``); truth_xy: (M, 2) metres, truth
    frame: occupied cell centres or wall-band points. params: the tunables (tolerance, voxel,
    search, finalists; see :class:`~pcmapq.align.params.AlignParams`).
    init: a starting map -> truth transform; given, the global search is skipped and ICP starts
    there (its scale dropped unless ``scale``). refine: False with no ``init`` scores the
    identity ("none"); False with ``init`` scores ``init`` as it is ("init").
    scale: also estimate the scale, for a map in an unknown unit (see :func:`align_similarity`).
    target: these truth points prepared by :class:`RigidTarget` (used without ``scale``, when
    it fits ``params``): the same result, without the truth's work.
    free: the map's free space and the truth's solid and known cells (rigid alignment): the
    search and the choice among its poses weigh each pose by it, and the result gives its
    contradiction and free_on_truth.
    """
    map_xy = np.asarray(map_xy, dtype=np.float64).reshape(-1, 2)
    truth_xy = np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2)
    if scale:
        return align_similarity(map_xy, truth_xy, params, init=init, refine=refine)
    if target is None or not target.fits(params):
        target = RigidTarget(truth_xy, params)
    return _align_rigid(map_xy, target, params, init, refine, free)


def _align_rigid(map_xy: np.ndarray, target: RigidTarget, params: AlignParams,
                 init: Similarity2D | None, refine: bool,
                 free: FreeSpace | None = None) -> Alignment:
    """:func:`align` with scale 1: the search of :func:`~pcmapq.align.coarse.coarse_search`,
    Open3D point-to-point ICP stages (:data:`~pcmapq.align.point_to_point.DEFAULT_SCHEDULE`,
    the first widened to twice the search's cell; see :func:`_icp_inputs` for a thinned map),
    then point-to-line on the winner."""
    voxel, tolerance = params.voxel, params.tolerance
    map_ds, map_voxel = thinned(map_xy, voxel, params.max_points)
    truth_ds, tree = target.points, target.tree
    start = Similarity2D() if init is None else init
    if len(map_ds) == 0 or len(truth_ds) == 0:
        return Alignment(start, 0.0, 0.0, tolerance, "none")
    clear = None if free is None else free.clear(map_ds, voxel)

    def scored(tf: Similarity2D) -> Alignment:
        fit = _scored(map_ds, tree, tf, tolerance)
        return fit if free is None else replace(
            fit, contradiction=free.contradiction(clear, tf),
            free_on_truth=free.on_truth(clear, tf))

    if not refine:
        return replace(scored(start), method="none" if init is None else "init")
    (first_dist, first_voxel), *fine_stages = DEFAULT_SCHEDULE
    search = None
    if init is None:
        resolution = auto_resolution(map_ds) if params.resolution is None else params.resolution
        search = coarse_search(map_ds, truth_ds, resolution=resolution, top_k=params.top_k,
                               free=free)
        if search.cell > params.finest:
            search = descend(search, map_ds, truth_ds, finest=params.finest, beam=params.beam,
                             top_k=params.top_k)
        first_dist = max(first_dist, 2 * search.cell)
    icp_map, schedule = _icp_inputs(map_ds, map_voxel > voxel,
                                    ((first_dist, first_voxel), *fine_stages))
    icp = IcpTarget(truth_ds, schedule, target.clouds)
    finals: list[Alignment] = []
    best = refine_best(
        _starts(search, start),
        lambda tf: refine_point_to_point(icp_map, icp, tf, stages=slice(1)),
        lambda tf: refine_point_to_point(icp_map, icp, tf, stages=slice(1, None)), scored,
        params.finalists_for(scale=False), finals_out=finals)
    # Point-to-line on the winner only: finishing both finalists moves no bench_align pose.
    tf = refine_point_to_line(map_ds, target.lines, best, fine_stages[-1][0])
    return _labelled(scored(tf), search, "coarse+icp", finals)


def _icp_inputs(map_ds: np.ndarray, thinned: bool, schedule: tuple[tuple[float, float], ...]
                ) -> tuple[np.ndarray, tuple[tuple[float, float], ...]]:
    """The map points (N, 2, metres, map frame) and the (max distance, voxel) stages, metres, of
    the point-to-point ICP: ``map_ds`` and ``schedule`` as they are; for a ``thinned`` map,
    ICP_POINTS of its points and every stage's truth at THINNED_TRUTH_VOXEL."""
    if not thinned:
        return map_ds, schedule
    return (evenly(map_ds, ICP_POINTS),
            tuple((distance, THINNED_TRUTH_VOXEL) for distance, _ in schedule))


def align_similarity(map_xy: np.ndarray, truth_xy: np.ndarray,
                     params: AlignParams = AlignParams(), *, init: Similarity2D | None = None,
                     refine: bool = True) -> Alignment:
    """Align a map of unknown unit to the truth: scale, rotation and translation, with no
    initial guess needed; never fails on a bad match.

    map_xy: (N, 2) in the map's own unit, map frame; truth_xy: (M, 2) truth units (metres),
    truth frame. Every length of ``params`` is in truth units; the map is downsampled to
    ``voxel`` truth units at the current scale. The search over scale, yaw and position
    (:func:`~pcmapq.align.coarse.similarity_search`) works on cells of ``resolution`` (default:
    the truth's radius / 20), which also sets the scaled ICP stages
    (:func:`~pcmapq.align.similarity_icp.similarity_schedule`); the point-to-line finish, with
    scale, pairs points within ``tolerance``. init: a starting similarity (its scale kept),
    skips the search. fitness and rmse_m are in the truth frame, as in :func:`align`.
    """
    voxel, tolerance = params.voxel, params.tolerance
    map_xy = np.asarray(map_xy, dtype=np.float64).reshape(-1, 2)
    truth_ds = voxel_centroids(truth_xy, voxel)
    start = Similarity2D() if init is None else init
    if len(map_xy) == 0 or len(truth_ds) < 2:  # the truth must have a size
        return Alignment(start, 0.0, 0.0, tolerance, "none")
    tree = cKDTree(truth_ds)

    def scored(tf: Similarity2D) -> Alignment:
        """Scored on the map downsampled to ``voxel`` truth units at ``tf``'s scale."""
        return _scored(_map_at_scale(map_xy, tf, voxel), tree, tf, tolerance)

    if not refine:
        return replace(scored(start), method="none" if init is None else "init")
    resolution = (similarity_resolution(truth_ds) if params.resolution is None
                  else params.resolution)
    search = None
    if init is None:
        search = similarity_search(map_xy, truth_ds, scale_range=params.scale_range,
                                   resolution=resolution, top_k=params.top_k)
    first, *rest = similarity_schedule(resolution, tolerance, voxel)
    rough, fine = SimilarityTarget(truth_ds, (first,)), SimilarityTarget(truth_ds, tuple(rest))
    lines = LineTarget(truth_ds, tree)

    def finish(tf: Similarity2D) -> Similarity2D:
        tf = refine_similarity(map_xy, fine, tf)
        return refine_point_to_line(_map_at_scale(map_xy, tf, voxel), lines, tf, tolerance,
                                    with_scale=True)

    def covered(tf: Similarity2D) -> float:
        """Share of the truth's points within ``tolerance`` of the map's, at ``tf``."""
        near = cKDTree(tf.apply(_map_at_scale(map_xy, tf, voxel)))
        return float(np.mean(np.isfinite(
            near.query(truth_ds, distance_upper_bound=tolerance)[0])))

    finals: list[Alignment] = []
    best = refine_best(_starts(search, start), lambda tf: refine_similarity(map_xy, rough, tf),
                       finish, scored, params.finalists_for(scale=True), covered=covered,
                       finals_out=finals)
    return _labelled(scored(best), search, "similarity+icp", finals)


def _starts(search: Search | None, init: Similarity2D) -> list[Similarity2D]:
    """The search's candidate poses, best first; ``init`` alone when there was no search."""
    return [init] if search is None else [c.transform for c in search.candidates]


def _labelled(best: Alignment, search: Search | None, method: str,
              finals: list[Alignment] = ()) -> Alignment:
    """``best`` with its method ("init+icp" with no search), its distinctiveness and the two
    best distinct refined ``finals`` (best first; one pose within SAME_POSE_M and
    SAME_POSE_DEG of a better one is the same) with their support."""
    if search is None:
        return replace(best, method="init+icp")
    distinct = [f for i, f in enumerate(finals)
                if not any(same_pose(f.transform, g.transform) for g in finals[:i])]
    return replace(best, method=method, distinctiveness=distinctiveness(search, best.transform),
                   poses=tuple((f.transform, support(f)) for f in distinct[:2]))


def _scored(map_xy: np.ndarray, tree: cKDTree, tf: Similarity2D, tolerance: float) -> Alignment:
    """``tf`` scored on the map (N, 2, map frame) against the truth tree; method unset."""
    fitness, rmse = _score_tree(map_xy, tree, tf, tolerance)
    return Alignment(tf, fitness, rmse, tolerance, "")


def _map_at_scale(map_xy: np.ndarray, tf: Similarity2D, voxel: float) -> np.ndarray:
    """The map (N, 2, map units) downsampled to ``voxel`` truth units under ``tf``'s scale."""
    return voxel_centroids(map_xy, voxel / tf.scale)
