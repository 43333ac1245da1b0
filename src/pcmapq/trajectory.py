"""Trajectory errors as evo (MichaelGrupp/evo) defines them: the absolute pose error (APE) of an
estimated trajectory against a reference, after an optional SE(3) or Sim(3) alignment or an
alignment of the first poses, and the relative pose error (RPE) over pairs of poses a number of
poses or metres apart. Poses are (N, 4, 4) matrices, world <- body, paired by index (no
timestamp association); translations in metres, angles in degrees.

- APE of pose i: E_i = inv(ref_i) est_i; ``translation`` ||t(E_i)|| (metres), ``rotation`` the
  angle of R(E_i) (degrees), ``full`` ||E_i - I|| (Frobenius).
- RPE of a pair (i, j): E = inv(inv(ref_i) ref_j) inv(est_i) est_j, with the same three parts.
- Alignment (evo's ``--align``/``--correct_scale``): Umeyama's least-squares rotation, translation
  (and scale) taking the estimated positions onto the reference's, applied to every estimated
  pose; ``--align_origin``: the transform that puts the first estimated pose on the first
  reference pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.errors import InputError

#: The parts of a pose error, as evo's ``PoseRelation`` names them.
RELATIONS = ("translation", "rotation", "full")


@dataclass(frozen=True)
class ErrorStats:
    """evo's statistics of a set of errors: rmse, mean, median, std (population), min, max,
    sse (sum of squares), and how many."""

    rmse: float
    mean: float
    median: float
    std: float
    min: float
    max: float
    sse: float
    count: int


def statistics(errors: np.ndarray) -> ErrorStats:
    """The statistics of ``errors`` (nonempty, 1D)."""
    e = np.asarray(errors, dtype=np.float64)
    if e.size == 0:
        raise InputError("no pose pairs to compute an error over")
    sse = float(np.sum(e * e))
    return ErrorStats(float(np.sqrt(sse / e.size)), float(e.mean()), float(np.median(e)),
                      float(e.std()), float(e.min()), float(e.max()), sse, int(e.size))


def umeyama(source: np.ndarray, target: np.ndarray,
            with_scale: bool) -> tuple[np.ndarray, np.ndarray, float]:
    """R (3, 3), t (3,) and s minimising sum |target_i - (s R source_i + t)|^2 over points
    (N, 3), metres (Umeyama 1991; s = 1 unless ``with_scale``)."""
    x, y = np.asarray(source, dtype=np.float64), np.asarray(target, dtype=np.float64)
    if len(x) < 3 or x.shape != y.shape:
        raise InputError(f"alignment needs two sets of at least 3 paired positions, got "
                         f"{len(x)} and {len(y)}")
    mx, my = x.mean(axis=0), y.mean(axis=0)
    cov = (y - my).T @ (x - mx) / len(x)
    u, d, vt = np.linalg.svd(cov)
    sign = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2, 2] = -1.0
    r = u @ sign @ vt
    scale = float(np.trace(np.diag(d) @ sign) / ((x - mx) ** 2).sum(axis=1).mean()) \
        if with_scale else 1.0
    return r, my - scale * r @ mx, scale


def aligned(est: np.ndarray, ref: np.ndarray, align: bool = False, correct_scale: bool = False,
            align_origin: bool = False) -> np.ndarray:
    """The estimated poses moved as evo moves them: scaled and rigidly aligned to the reference
    by :func:`umeyama` (``align``, ``correct_scale``), or with their first pose put on the
    reference's (``align_origin``); as they are otherwise."""
    est, ref = _poses(est, "estimate"), _poses(ref, "reference")
    _paired(est, ref)
    if align or correct_scale:
        r, t, s = umeyama(est[:, :3, 3], ref[:, :3, 3], correct_scale)
        moved = est.copy()
        moved[:, :3, 3] *= s
        if align:
            move = np.eye(4)
            move[:3, :3], move[:3, 3] = r, t
            moved = move @ moved
        return moved
    if align_origin:
        return ref[0] @ np.linalg.inv(est[0]) @ est
    return est


def errors(e: np.ndarray, relation: str) -> np.ndarray:
    """One part of error matrices (K, 4, 4): ``translation`` metres, ``rotation`` degrees,
    ``full`` the Frobenius norm of E - I."""
    if relation == "translation":
        return np.linalg.norm(e[:, :3, 3], axis=1)
    if relation == "rotation":
        cos = (np.trace(e[:, :3, :3], axis1=1, axis2=2) - 1.0) / 2.0
        return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    if relation == "full":
        return np.linalg.norm(e - np.eye(4), axis=(1, 2))
    raise InputError(f"unknown pose relation {relation!r}: one of {', '.join(RELATIONS)}")


def ape(est: np.ndarray, ref: np.ndarray, relation: str = "translation",
        align: bool = False, correct_scale: bool = False,
        align_origin: bool = False) -> np.ndarray:
    """The absolute pose error of each pose (see the module docstring), after
    :func:`aligned`."""
    moved = aligned(est, ref, align, correct_scale, align_origin)
    return errors(np.linalg.inv(_poses(ref, "reference")) @ moved, relation)


def pairs_by_index(n: int, delta: int, all_pairs: bool = False) -> np.ndarray:
    """(K, 2) pose index pairs ``delta`` poses apart: consecutive (0, d), (d, 2d) ... or, with
    ``all_pairs``, (i, i + d) for every i (evo's ``filter_pairs_by_index``)."""
    if delta < 1:
        raise InputError(f"delta must be at least 1 pose, got {delta}")
    if all_pairs:
        i = np.arange(max(n - delta, 0))
        return np.column_stack([i, i + delta])
    ids = np.arange(0, n, delta)
    return np.column_stack([ids[:-1], ids[1:]])


def pairs_by_path(positions: np.ndarray, delta: float, tol: float = 0.0,
                  all_pairs: bool = False) -> np.ndarray:
    """(K, 2) pose index pairs about ``delta`` metres apart along the path (evo's
    ``filter_pairs_by_path``): consecutive poses where the path travelled since the last one
    reaches ``delta`` (the first once it does from pose 0); or, with ``all_pairs``, each pose i
    with the later pose whose path distance from it is nearest ``delta``, kept within ``tol``
    metres."""
    p = np.asarray(positions, dtype=np.float64)
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    travelled = np.r_[0.0, np.cumsum(steps)]
    if all_pairs:
        out = []
        for i in range(len(p) - 1):  # one search a pose, vectorised along the path
            ahead = travelled[i + 1:] - travelled[i]
            j = int(np.argmin(np.abs(ahead - delta)))
            if abs(ahead[j] - delta) <= tol:
                out.append((i, i + 1 + j))
        return np.array(out, dtype=np.int64).reshape(-1, 2)
    ids = _path_marks(np.r_[0.0, steps], delta)
    return np.column_stack([ids[:-1], ids[1:]]).astype(np.int64)


def _path_marks(steps: np.ndarray, delta: float) -> np.ndarray:
    """The poses where the path since the last mark (counted from pose 0) reaches ``delta``."""
    marks, since = [], 0.0
    for i, step in enumerate(steps.tolist()):  # a running sum that restarts: one pass
        since += step
        if since >= delta:
            marks.append(i)
            since = 0.0
    return np.array(marks, dtype=np.int64)


def rpe(est: np.ndarray, ref: np.ndarray, pairs: np.ndarray,
        relation: str = "translation") -> np.ndarray:
    """The relative pose error of each pair (i, j) of ``pairs`` (see the module docstring)."""
    est, ref = _poses(est, "estimate"), _poses(ref, "reference")
    _paired(est, ref)
    i, j = np.asarray(pairs, dtype=np.int64).T
    rel_ref = np.linalg.inv(ref[i]) @ ref[j]
    rel_est = np.linalg.inv(est[i]) @ est[j]
    return errors(np.linalg.inv(rel_ref) @ rel_est, relation)


def _poses(poses: np.ndarray, what: str) -> np.ndarray:
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] != (4, 4):
        raise InputError(f"the {what} must be (N, 4, 4) poses, got {p.shape}")
    return p


def _paired(est: np.ndarray, ref: np.ndarray) -> None:
    if len(est) != len(ref):
        raise InputError(f"{len(est)} estimated poses for {len(ref)} reference poses: they are "
                         "paired by index")
