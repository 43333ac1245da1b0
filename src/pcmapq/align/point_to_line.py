"""2D point-to-line ICP: points slide along the truth's walls, so it converges exactly where
point-to-point ICP locks onto the lattice of two gridded clouds; it finishes every refinement."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.transform import Similarity2D


def line_normals(xy: np.ndarray, tree: cKDTree, neighbours: int = 8) -> np.ndarray:
    """Unit normal (N, 2) of the local line through each point (N >= 2, 2, metres): the
    direction of least spread of its nearest neighbours (PCA); ``tree`` holds the points."""
    _, idx = tree.query(xy, k=min(neighbours, len(xy)))
    near = xy[idx] - xy[idx].mean(axis=1, keepdims=True)
    _, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", near, near))
    return vectors[:, :, 0]


class LineTarget:
    """The truth prepared once for point-to-line ICP from many starts: its points (M, 2, metres,
    truth frame), their KD-tree and line normals (none under 3 points: nothing to refine on)."""

    def __init__(self, truth_xy: np.ndarray) -> None:
        self.points = np.asarray(truth_xy, dtype=np.float64).reshape(-1, 2)
        self.tree = cKDTree(self.points)
        self.normals = (line_normals(self.points, self.tree) if len(self.points) >= 3
                        else np.empty((0, 2)))


def refine_point_to_line(map_xy: np.ndarray, target: LineTarget, init: Similarity2D,
                         max_distance: float = 0.2, iterations: int = 30,
                         with_scale: bool = False) -> Similarity2D:
    """2D point-to-line ICP (Gauss-Newton with Tukey weights) of the map (N, 2, metres, map
    frame) onto the truth (``target``), from ``init``; pairs farther apart than
    ``max_distance`` metres are ignored. Returns the map -> truth transform: scale 1, or with
    ``with_scale`` the scale refined too (the map then in any unit, starting at ``init``'s)."""
    if len(target.normals) == 0:
        return init
    truth_xy, normals, tree = target.points, target.normals, target.tree
    tf = init if with_scale else Similarity2D(init.tx, init.ty, init.yaw)
    for _ in range(iterations):
        p = tf.apply(map_xy)
        dist, j = tree.query(p, distance_upper_bound=max_distance)
        ok = np.isfinite(dist)
        if ok.sum() < 3:
            break
        p, n = p[ok], normals[j[ok]]
        r = np.einsum("ni,ni->n", p - truth_xy[j[ok]], n)
        # residual change for a step (dx, dy, dyaw[, ds]) about the origin:
        # n . (d + dyaw * perp(p) [+ ds * p])
        jac = np.column_stack([n[:, 0], n[:, 1], n[:, 1] * p[:, 0] - n[:, 0] * p[:, 1]])
        if with_scale:
            jac = np.column_stack([jac, np.einsum("ni,ni->n", n, p)])
        scale = max(1.4826 * float(np.median(np.abs(r))), 1e-3)
        w = np.clip(1.0 - (r / (4.685 * scale)) ** 2, 0.0, None) ** 2
        step = np.linalg.lstsq(jac.T @ (jac * w[:, None]), -jac.T @ (w * r), rcond=None)[0]
        if with_scale:
            update = Similarity2D(*step[:3], 1.0 + step[3])
            tf = Similarity2D.from_matrix(update.matrix @ tf.matrix)
        else:
            tf = Similarity2D.from_matrix(Similarity2D(*step).matrix @ tf.matrix)
            tf = Similarity2D(tf.tx, tf.ty, tf.yaw)  # keep scale exactly 1
        if np.abs(step[:2]).max() < 1e-6 and np.abs(step[2:]).max() < 1e-7:
            break
    return tf
