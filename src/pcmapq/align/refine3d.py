"""Local refinement of a 3D registration: point-to-plane ICP by small_gicp, coarse to fine.

Frames: transforms take source points to the target frame, ``p_target = T @ p_source``; metres.

Three stages with correspondence distances 2, 1 and 0.5 ``voxel``, the last on clouds
downsampled at ``voxel / 2``; target normals from each target point's 20 nearest neighbours.
The registration's sums run on one thread, so the result is the same bit for bit from run to run
(on more, which points each thread sums depends on their timing); the target's KD-tree and
normals, each point's own, are built on every core: the same tree and normals, bit for bit.

small_gicp over Open3D's ICP: repeatable without holding Open3D to one thread, and closer to
the reference poses (docs/benchmarks.md, "Choices behind the code").

small_gicp holds Python's lock while it registers, so no other thread of the process runs
meanwhile. Clouds of CHILD_POINTS or more (all stages' clouds counted) are therefore refined
in a child process (:mod:`pcmapq.core.child`): the same transform bit for bit, while the
evaluation's other threads (the truth's figures) go on beside it.
"""

from __future__ import annotations

import os

import numpy as np
import small_gicp

from pcmapq.core.child import CHILD_POINTS, in_child

__all__ = ["last_reach", "refine"]

#: ICP stages: (max correspondence distance, downsampling voxel), in units of ``voxel``.
ICP_STAGES = ((2.0, 1.0), (1.0, 1.0), (0.5, 0.5))
#: Iterations per ICP stage, at most.
ICP_ITERATIONS = 50
#: A stage stops when an update turns less than this (radians) and moves less (metres).
CONVERGED = 1e-4
#: Neighbours of a target point that fit its normal.
NORMAL_NEIGHBOURS = 20
#: Threads that build a target's KD-tree and normals: the registration holds Python's lock
#: meanwhile, so the pipeline's other threads leave the cores to it.
PREPARE_THREADS = os.cpu_count() or 1

Levels = dict[float, tuple[np.ndarray, np.ndarray]]


def refine(source: np.ndarray, target: np.ndarray, guess: np.ndarray, voxel: float,
           coarse: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Point-to-plane ICP from ``guess`` (4x4 source -> target), coarse to fine; 4x4.

    source (N, 3), target (M, 3): the whole clouds, metres; coarse: both already downsampled
    at ``voxel`` (metres, the working resolution).
    """
    # imported here: the child process that runs _stages imports this module, and starts
    # sooner with NumPy and small_gicp alone (SciPy and Numba come with the voxels)
    from pcmapq.core.voxels import voxel_centroids

    levels: Levels = {1.0: coarse}
    for _, units in ICP_STAGES:
        if units not in levels:
            levels[units] = (voxel_centroids(source, voxel * units),
                             voxel_centroids(target, voxel * units))
    guess = np.asarray(guess, dtype=np.float64)
    if sum(len(src) + len(tgt) for src, tgt in levels.values()) >= CHILD_POINTS:
        return in_child("the 3D ICP", _stages, levels, guess, voxel)
    return _stages(levels, guess, voxel)


def _stages(levels: Levels, guess: np.ndarray, voxel: float) -> np.ndarray:
    """The ICP stages from ``guess`` (4x4) on ``levels`` (source and target downsampled at each
    stage's voxel, in units of ``voxel``, metres); 4x4."""
    prepared = {units: _prepared(*clouds) for units, clouds in levels.items()}
    transform = guess
    for distance_units, voxel_units in ICP_STAGES:
        src, tgt, tree = prepared[voxel_units]
        result = small_gicp.align(tgt, src, tree, init_T_target_source=transform,
                                  registration_type="PLANE_ICP",
                                  max_correspondence_distance=voxel * distance_units,
                                  num_threads=1, max_iterations=ICP_ITERATIONS,
                                  rotation_epsilon=CONVERGED, translation_epsilon=CONVERGED)
        transform = np.array(result.T_target_source, dtype=np.float64)
    return transform


def last_reach(voxel: float) -> float:
    """How far apart a source and a target point may be to pair in the last ICP stage,
    metres, at the working resolution ``voxel`` (metres)."""
    return ICP_STAGES[-1][0] * voxel


def _prepared(source: np.ndarray, target: np.ndarray
              ) -> tuple[small_gicp.PointCloud, small_gicp.PointCloud, small_gicp.KdTree]:
    """small_gicp clouds of source (N, 3) and target (M, 3), metres, the target with normals and
    its KD-tree."""
    src, tgt = small_gicp.PointCloud(source), small_gicp.PointCloud(target)
    tree = small_gicp.KdTree(tgt, num_threads=PREPARE_THREADS)
    small_gicp.estimate_normals(tgt, tree, num_neighbors=NORMAL_NEIGHBOURS,
                                num_threads=PREPARE_THREADS)
    return src, tgt, tree
