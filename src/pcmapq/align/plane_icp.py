"""small_gicp's point-to-plane ICP, with each source point's nearest target point searched again
only where it may have changed.

Frames: ``T`` (4x4) takes source points to the target frame, ``p_target = T @ p_source``;
metres.

The cost and the steps are small_gicp's ``PLANE_ICP`` (``PointToPlaneICPFactor``, its
Levenberg-Marquardt optimizer, one thread): each source point ``p`` paired with its nearest
target point ``q`` within ``max_distance`` contributes ``0.5 |n * (q - T p)|^2`` (``n`` the target
point's normal, taken axis by axis); a step solves ``(H + lambda I) delta = -b``, is kept when
the cost on the same pairs falls (``lambda`` divided by 10) or tried again with ``lambda`` 10
times larger (10 tries at most), and moves ``T <- T exp(delta)``; the stage ends when a kept
step turns less than ``rotation_eps`` radians and moves less than ``translation_eps`` metres, or
after ``iterations`` steps. The transform is small_gicp's to about 1e-14 (the sums' order
differs in the last bits), the iterations the same.

What small_gicp does at every step, a nearest-neighbour search of every source point in the
target's KD-tree, is most of its time; between steps the pose moves by millimetres. So each
point keeps the CANDIDATES nearest target points found at a pose, and how far the farthest of
them was: at a later pose, the nearest of the candidates is the nearest of all target points
while it is nearer than that radius less the distance the point has moved since (any other
target point was at least the radius away then). Points for which that cannot be shown are
searched again (small_gicp's KD-tree, on ``threads`` threads: each point's search is its own,
so the result does not depend on them), but for points shown to be farther than the stage's
``max_distance`` from every target point (the nearer of their nearest candidate and that radius
less the distance moved): they pair with no target point whichever is nearest, so their
nearest candidate stands in. The pairs that count are those small_gicp finds, but for two
target points at exactly the same distance.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
import small_gicp

__all__ = ["Fit", "Nearest", "plane_icp", "prepared"]

#: Nearest target points kept per source point.
CANDIDATES = 4
#: small_gicp's Levenberg-Marquardt settings: the first damping, its factor, tries per step.
INIT_LAMBDA, LAMBDA_FACTOR, TRIES = 1e-3, 10.0, 10


@numba.njit(cache=True, nogil=True)
def _linearize(source: np.ndarray, target: np.ndarray, normals: np.ndarray, pair: np.ndarray,
               rotation: np.ndarray, shift: np.ndarray, max_sq: float,
               inlier: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """H (6x6), b (6,) and the cost of the pairs within ``max_sq`` (squared metres) at the pose
    (``rotation``, ``shift``); ``inlier`` (N,) set to which pairs count. Turns first, then
    translations, as small_gicp orders them. The sums are kept in scalars (the upper triangle
    of H; the lower is the same products), each added in the points' and axes' order."""
    h00 = h01 = h02 = h03 = h04 = h05 = h11 = h12 = h13 = h14 = h15 = 0.0
    h22 = h23 = h24 = h25 = h33 = h34 = h35 = h44 = h45 = h55 = 0.0
    g0 = g1 = g2 = g3 = g4 = g5 = cost = 0.0
    for i in range(source.shape[0]):
        j = pair[i]
        p0, p1, p2 = source[i, 0], source[i, 1], source[i, 2]
        e0 = target[j, 0] - (rotation[0, 0] * p0 + rotation[0, 1] * p1 + rotation[0, 2] * p2
                             + shift[0])
        e1 = target[j, 1] - (rotation[1, 0] * p0 + rotation[1, 1] * p1 + rotation[1, 2] * p2
                             + shift[1])
        e2 = target[j, 2] - (rotation[2, 0] * p0 + rotation[2, 1] * p1 + rotation[2, 2] * p2
                             + shift[2])
        if e0 ** 2 + e1 ** 2 + e2 ** 2 > max_sq:
            inlier[i] = False
            continue
        inlier[i] = True
        for k in range(3):
            nk = normals[j, k]
            err = nk * (e0 if k == 0 else e1 if k == 1 else e2)
            ra, rb, rc = rotation[k, 0], rotation[k, 1], rotation[k, 2]
            a0, a1 = nk * (rb * p2 - rc * p1), nk * (rc * p0 - ra * p2)
            a2 = nk * (ra * p1 - rb * p0)
            a3, a4, a5 = -nk * ra, -nk * rb, -nk * rc
            g0 += a0 * err
            g1 += a1 * err
            g2 += a2 * err
            g3 += a3 * err
            g4 += a4 * err
            g5 += a5 * err
            h00 += a0 * a0
            h01 += a0 * a1
            h02 += a0 * a2
            h03 += a0 * a3
            h04 += a0 * a4
            h05 += a0 * a5
            h11 += a1 * a1
            h12 += a1 * a2
            h13 += a1 * a3
            h14 += a1 * a4
            h15 += a1 * a5
            h22 += a2 * a2
            h23 += a2 * a3
            h24 += a2 * a4
            h25 += a2 * a5
            h33 += a3 * a3
            h34 += a3 * a4
            h35 += a3 * a5
            h44 += a4 * a4
            h45 += a4 * a5
            h55 += a5 * a5
            cost += 0.5 * err * err
    hessian = np.array([[h00, h01, h02, h03, h04, h05], [h01, h11, h12, h13, h14, h15],
                        [h02, h12, h22, h23, h24, h25], [h03, h13, h23, h33, h34, h35],
                        [h04, h14, h24, h34, h44, h45], [h05, h15, h25, h35, h45, h55]])
    return hessian, np.array([g0, g1, g2, g3, g4, g5]), cost


@numba.njit(cache=True, nogil=True)
def _cost(source: np.ndarray, target: np.ndarray, normals: np.ndarray, pair: np.ndarray,
          inlier: np.ndarray, rotation: np.ndarray, shift: np.ndarray) -> float:
    """The cost of the same pairs (``inlier``) at another pose."""
    cost = 0.0
    for i in range(source.shape[0]):
        if not inlier[i]:
            continue
        j = pair[i]
        p0, p1, p2 = source[i, 0], source[i, 1], source[i, 2]
        for k in range(3):
            err = normals[j, k] * (target[j, k] - (rotation[k, 0] * p0 + rotation[k, 1] * p1
                                                   + rotation[k, 2] * p2 + shift[k]))
            cost += 0.5 * err * err
    return cost


@numba.njit(cache=True, nogil=True)
def _kept(source: np.ndarray, rotation: np.ndarray, shift: np.ndarray, target: np.ndarray,
          near: np.ndarray, reach: np.ndarray, seen_at: np.ndarray, pair: np.ndarray,
          again: np.ndarray, max_distance: float) -> int:
    """Each source point's nearest target point among its candidates ``near`` (N, K) into
    ``pair`` where it is provably the nearest of all, or where every target point is provably
    farther than ``max_distance`` metres (module docstring); the other points' indices into
    ``again``; returns how many."""
    count = 0
    for i in range(source.shape[0]):
        p0, p1, p2 = source[i, 0], source[i, 1], source[i, 2]
        x0 = rotation[0, 0] * p0 + rotation[0, 1] * p1 + rotation[0, 2] * p2 + shift[0]
        x1 = rotation[1, 0] * p0 + rotation[1, 1] * p1 + rotation[1, 2] * p2 + shift[1]
        x2 = rotation[2, 0] * p0 + rotation[2, 1] * p1 + rotation[2, 2] * p2 + shift[2]
        moved = np.sqrt((x0 - seen_at[i, 0]) ** 2 + (x1 - seen_at[i, 1]) ** 2
                        + (x2 - seen_at[i, 2]) ** 2)
        best, best_sq = -1, np.inf
        for c in range(near.shape[1]):
            j = near[i, c]
            sq = (target[j, 0] - x0) ** 2 + (target[j, 1] - x1) ** 2 + (target[j, 2] - x2) ** 2
            if sq < best_sq:
                best, best_sq = j, sq
        best_d, bound = np.sqrt(best_sq), reach[i] - moved  # bound: the others' least
        if best_d < bound or (best_d > max_distance and bound > max_distance):
            pair[i] = best
        else:
            again[count] = i
            count += 1
    return count


class Fit(NamedTuple):
    """transform: 4x4 source -> target. steps: the index of the last step (small_gicp's
    ``iterations``). hessian: the 6 x 6 Hessian of the last linearisation (turns first;
    small_gicp's ``H``), inliers: the pairs it counted (small_gicp's ``num_inliers``)."""

    transform: np.ndarray
    steps: int
    hessian: np.ndarray
    inliers: int


class Nearest:
    """Each source point's nearest target point, kept from pose to pose (module docstring).

    source (N, 3), target (M, 3): metres; tree: small_gicp's KD-tree of the target, or of the
    target moved by ``offset`` (3,) metres (one tree shared by sources worked on about their
    own centres); threads: threads of the searches. ``searched`` counts the points searched."""

    def __init__(self, source: np.ndarray, target: np.ndarray, tree: small_gicp.KdTree,
                 threads: int = 1, offset: np.ndarray | None = None) -> None:
        n = len(source)
        self.source, self.target, self.tree, self.threads = source, target, tree, threads
        self.offset = None if offset is None else np.asarray(offset, dtype=np.float64)
        self.k = min(CANDIDATES, len(target))
        self.near = np.zeros((n, self.k), np.int64)
        self.reach = np.full(n, -np.inf)  # no candidates yet: every point is searched
        self.seen_at = np.zeros((n, 3))
        self.pair = np.zeros(n, np.int64)
        self._again = np.empty(n, np.int64)
        self.searched = 0

    def at(self, rotation: np.ndarray, shift: np.ndarray,
           max_distance: float = np.inf) -> np.ndarray:
        """(N,) index of each source point's nearest target point at the pose; of a point
        farther than ``max_distance`` metres from every target point, one of its candidates."""
        count = _kept(self.source, rotation, shift, self.target, self.near, self.reach,
                      self.seen_at, self.pair, self._again, max_distance)
        if count:
            again = self._again[:count].copy()
            moved = self.source[again] @ rotation.T + shift
            query = moved if self.offset is None else moved + self.offset
            found, sq = self.tree.batch_knn_search(query, self.k, num_threads=self.threads)
            found = found.astype(np.int64)
            self.near[again], self.reach[again] = found, np.sqrt(sq[:, -1])
            self.seen_at[again], self.pair[again] = moved, found[:, 0]
            self.searched += count
        return self.pair


def prepared(source: np.ndarray, target: np.ndarray, neighbours: int, threads: int = 1
             ) -> tuple[Nearest, np.ndarray]:
    """What :func:`plane_icp` needs of a source (N, 3) and a target (M, 3), metres: the
    source's kept nearest target points (:class:`Nearest`) in small_gicp's KD-tree of the
    target, and the target's unit normals (M, 3) from each point's ``neighbours`` nearest
    (small_gicp's). Tree, normals and searches on ``threads`` threads, each point's its own:
    the same whatever the threads."""
    cloud = small_gicp.PointCloud(target)
    tree = small_gicp.KdTree(cloud, num_threads=threads)
    small_gicp.estimate_normals(cloud, tree, num_neighbors=neighbours, num_threads=threads)
    nearest = Nearest(np.ascontiguousarray(source, dtype=np.float64),
                      np.ascontiguousarray(cloud.points()[:, :3]), tree, threads=threads)
    return nearest, np.ascontiguousarray(cloud.normals()[:, :3])


def plane_icp(nearest: Nearest, normals: np.ndarray, guess: np.ndarray, max_distance: float,
              iterations: int, rotation_eps: float, translation_eps: float) -> Fit:
    """small_gicp's ``PLANE_ICP`` (module docstring) from ``guess`` (4x4) between the clouds of
    ``nearest``, the target's unit ``normals`` (M, 3)."""
    source, target = nearest.source, nearest.target
    transform = np.array(guess, dtype=np.float64)
    inlier = np.zeros(len(source), np.bool_)
    damping, last = INIT_LAMBDA, 0
    hessian = np.zeros((6, 6))
    for step in range(iterations):
        last = step
        rotation, shift = np.ascontiguousarray(transform[:3, :3]), transform[:3, 3].copy()
        pair = nearest.at(rotation, shift, max_distance)
        hessian, gradient, cost = _linearize(source, target, normals, pair, rotation, shift,
                                             max_distance * max_distance, inlier)
        kept, converged = False, False
        for _ in range(TRIES):
            delta = np.linalg.solve(hessian + damping * np.eye(6), -gradient)
            moved = transform @ se3_exp(delta)
            if _cost(source, target, normals, pair, inlier,
                     np.ascontiguousarray(moved[:3, :3]), moved[:3, 3].copy()) < cost:
                converged = (np.linalg.norm(delta[:3]) <= rotation_eps
                             and np.linalg.norm(delta[3:]) <= translation_eps)
                transform, damping, kept = moved, damping / LAMBDA_FACTOR, True
                break
            damping *= LAMBDA_FACTOR
        if not kept or converged:
            break
    return Fit(transform, last, hessian, int(np.count_nonzero(inlier)))


def se3_exp(delta: np.ndarray) -> np.ndarray:
    """The 4x4 transform of the twist ``delta`` (turn (3,) radians, then translation (3,)
    metres), as small_gicp's ``se3_exp``."""
    omega = delta[:3]
    theta_sq = float(omega @ omega)
    theta = np.sqrt(theta_sq)
    skew = np.array([[0.0, -omega[2], omega[1]], [omega[2], 0.0, -omega[0]],
                     [-omega[1], omega[0], 0.0]])
    out = np.eye(4)
    if theta_sq < 1e-10:  # small_gicp's series of the quaternion
        imag = 0.5 - theta_sq / 48.0 + theta_sq * theta_sq / 3840.0
        real = 1.0 - theta_sq / 8.0 + theta_sq * theta_sq / 384.0
    else:
        imag, real = np.sin(0.5 * theta) / theta, np.cos(0.5 * theta)
    out[:3, :3] = _rotation(real, imag * omega)
    if theta < 1e-10:
        out[:3, 3] = out[:3, :3] @ delta[3:]
    else:
        square = theta * theta
        v = (np.eye(3) + (1.0 - np.cos(theta)) / square * skew
             + (theta - np.sin(theta)) / (square * theta) * (skew @ skew))
        out[:3, 3] = v @ delta[3:]
    return out


def _rotation(w: float, xyz: np.ndarray) -> np.ndarray:
    """The rotation matrix of the unit quaternion (w, x, y, z), as Eigen writes it."""
    x, y, z = xyz
    tx, ty, tz = 2.0 * x, 2.0 * y, 2.0 * z
    twx, twy, twz = tx * w, ty * w, tz * w
    txx, txy, txz = tx * x, ty * x, tz * x
    tyy, tyz, tzz = ty * y, tz * y, tz * z
    return np.array([[1.0 - (tyy + tzz), txy - twz, txz + twy],
                     [txy + twz, 1.0 - (txx + tzz), tyz - twx],
                     [txz - twy, tyz + twx, 1.0 - (txx + tyy)]])
