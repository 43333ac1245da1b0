"""Local refinement of a 3D registration: small_gicp's point-to-plane ICP, coarse to fine.

Frames: transforms take source points to the target frame, ``p_target = T @ p_source``; metres.

Three stages with correspondence distances 2, 1 and 0.5 ``voxel``, the last on clouds
downsampled at ``voxel / 2``; target normals from each target point's 20 nearest neighbours.
The target's KD-tree and normals are small_gicp's, built on every core (each point's own: the
same tree and normals, bit for bit). The stages are small_gicp's ``PLANE_ICP`` as
:mod:`pcmapq.align.plane_icp` computes it: its transform to about 1e-14, in about a quarter of
its time on a 20-scan KITTI pair, since a source point's nearest target point is searched again
only where it may have changed (the first two stages, on the same clouds, share what they
found). Its sums run on one thread, so the result is the same bit for bit from run to run,
and its loops leave Python's lock to the evaluation's other threads (the truth's figures)
while they run.

small_gicp over Open3D's ICP: repeatable without holding Open3D to one thread, and closer to
the reference poses (docs/benchmarks.md, "Choices behind the code").
"""

from __future__ import annotations

import os

import numpy as np

__all__ = ["last_reach", "refine"]

#: ICP stages: (max correspondence distance, downsampling voxel), in units of ``voxel``.
ICP_STAGES = ((2.0, 1.0), (1.0, 1.0), (0.5, 0.5))
#: Iterations per ICP stage, at most.
ICP_ITERATIONS = 50
#: A stage stops when an update turns less than this (radians) and moves less (metres).
CONVERGED = 1e-4
#: Neighbours of a target point that fit its normal.
NORMAL_NEIGHBOURS = 20
#: Threads that build a target's KD-tree and normals and search its nearest neighbours.
PREPARE_THREADS = os.cpu_count() or 1


def refine(source: np.ndarray, target: np.ndarray, guess: np.ndarray, voxel: float,
           levels: dict[float, tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """Point-to-plane ICP from ``guess`` (4x4 source -> target), coarse to fine; 4x4.

    source (N, 3), target (M, 3): the whole clouds, metres. levels: both clouds downsampled,
    by voxel in units of ``voxel`` (metres, the working resolution): at least ``1.0``'s; the
    stages' others are added to it.
    """
    # Numba's loops: loaded when two clouds are registered
    from pcmapq.align.plane_icp import plane_icp, prepared
    from pcmapq.core.voxels import voxel_centroids

    for _, units in ICP_STAGES:
        if units not in levels:
            levels[units] = (voxel_centroids(source, voxel * units),
                             voxel_centroids(target, voxel * units))
    nearest, normals = {}, {}
    for units in dict.fromkeys(units for _, units in ICP_STAGES):
        nearest[units], normals[units] = prepared(*levels[units], NORMAL_NEIGHBOURS,
                                                  PREPARE_THREADS)
    transform = np.asarray(guess, dtype=np.float64)
    for distance_units, voxel_units in ICP_STAGES:
        transform = plane_icp(nearest[voxel_units], normals[voxel_units], transform,
                              voxel * distance_units, ICP_ITERATIONS, CONVERGED,
                              CONVERGED).transform
    return transform


def last_reach(voxel: float) -> float:
    """How far apart a source and a target point may be to pair in the last ICP stage,
    metres, at the working resolution ``voxel`` (metres)."""
    return ICP_STAGES[-1][0] * voxel

