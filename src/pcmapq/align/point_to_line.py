"""2D point-to-line ICP: points slide along the truth's walls, so it converges exactly where
point-to-point ICP locks onto the lattice of two gridded clouds; it finishes every refinement."""

from __future__ import annotations

from threading import Lock

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.core.nearest2d import NearestGrid
from pcmapq.core.transform import Similarity2D


def line_normals(tree: cKDTree, index: np.ndarray, neighbours: int = 8) -> np.ndarray:
    """Unit normal (K, 2) of the local line through each of the tree's points ``index`` (K,):
    the direction of least spread of the point's nearest neighbours among the tree's points
    (N >= 2, 2, metres; PCA). Each normal depends on its point alone, not on the others asked
    for with it."""
    points = tree.data
    _, idx = tree.query(points[index], k=min(neighbours, len(points)))
    near = points[idx] - points[idx].mean(axis=1, keepdims=True)
    _, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", near, near))
    return vectors[:, :, 0]


class LineTarget:
    """The truth prepared once for point-to-line ICP from many starts: its points (M, 2, metres,
    truth frame), their KD-tree and buckets (each ICP step's nearest points), and their line
    normals, each computed the first time a map point pairs with its truth point (a map of part
    of a large truth touches few of them)."""

    def __init__(self, truth_xy: np.ndarray, tree: cKDTree | None = None) -> None:
        """truth_xy: (M, 2) metres, truth frame; tree: a KD-tree of exactly these points, to
        share one already built (default: one is built)."""
        self.points = np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2)
        self.tree = cKDTree(self.points) if tree is None else tree
        self.grid = NearestGrid(self.points)
        self._normals = np.full((len(self.points), 2), np.nan)
        self._computing = Lock()

    def nearest(self, points: np.ndarray, max_distance: float) -> np.ndarray:
        """(K,) the index of each of ``points``' (K, 2, truth frame) nearest truth point, -1
        where none is nearer than ``max_distance`` metres: the KD-tree's, in about a third of
        its time for the few thousand points of an ICP step."""
        return self.grid.nearest(points, max_distance)

    def normals(self, index: np.ndarray) -> np.ndarray:
        """Unit line normals (K, 2) of the truth points ``index`` (K,), as
        :func:`line_normals`; none is computed twice. Needs at least 3 truth points. Safe
        from several threads at once."""
        with self._computing:
            got = self._normals[index]
            gap = np.isnan(got[:, 0])
            if gap.any():
                missing = np.unique(index[gap])
                self._normals[missing] = line_normals(self.tree, missing)
                got = self._normals[index]
            return got


def refine_point_to_line(map_xy: np.ndarray, target: LineTarget, init: Similarity2D,
                         max_distance: float = 0.2, iterations: int = 30,
                         with_scale: bool = False, settled: float = 1e-6) -> Similarity2D:
    """2D point-to-line ICP (Gauss-Newton with Tukey weights) of the map (N, 2, metres, map
    frame) onto the truth (``target``), from ``init``; pairs farther apart than
    ``max_distance`` metres are ignored; it stops once a step moves less than ``settled``
    metres (and a tenth of it in radians and scale). Returns the map -> truth transform: scale
    1, or with ``with_scale`` the scale refined too (the map then in any unit, starting at
    ``init``'s)."""
    if len(target.points) < 3:  # no lines to refine on
        return init
    truth_xy = target.points
    tf = init if with_scale else Similarity2D(init.tx, init.ty, init.yaw)
    for _ in range(iterations):
        p = tf.apply(map_xy)
        j = target.nearest(p, max_distance)
        ok = j >= 0
        if ok.sum() < 3:
            break
        p, n = p[ok], target.normals(j[ok])
        r = np.einsum("ni,ni->n", p - truth_xy[j[ok]], n)
        # residual change for a step (dx, dy, dyaw[, ds]) about the origin:
        # n . (d + dyaw * perp(p) [+ ds * p])
        jac = np.column_stack([n[:, 0], n[:, 1], n[:, 1] * p[:, 0] - n[:, 0] * p[:, 1]])
        if with_scale:
            jac = np.column_stack([jac, np.einsum("ni,ni->n", n, p)])
        scale = max(1.4826 * _median(np.abs(r)), 1e-3)
        w = np.clip(1.0 - (r / (4.685 * scale)) ** 2, 0.0, None) ** 2
        step = np.linalg.lstsq(jac.T @ (jac * w[:, None]), -jac.T @ (w * r), rcond=None)[0]
        if with_scale:
            update = Similarity2D(*step[:3], 1.0 + step[3])
            tf = Similarity2D.from_matrix(update.matrix @ tf.matrix)
        else:
            tf = Similarity2D.from_matrix(Similarity2D(*step).matrix @ tf.matrix)
            tf = Similarity2D(tf.tx, tf.ty, tf.yaw)  # keep scale exactly 1
        if np.abs(step[:2]).max() < settled and np.abs(step[2:]).max() < 0.1 * settled:
            break
    return tf


def _median(values: np.ndarray) -> float:
    """``np.median`` of finite ``values`` (K,), K >= 1: the same number, without numpy's
    checks (it runs once per ICP step)."""
    half = len(values) // 2
    if len(values) % 2:
        return float(np.partition(values, half)[half])
    low, high = np.partition(values, (half - 1, half))[half - 1:half + 1]
    return float((low + high) / 2)
