"""Trajectory errors, APE and RPE, defined as evo (github.com/MichaelGrupp/evo, 1.38) defines
them: poses are (N, 4, 4) SE(3) matrices in metres, errors in metres or degrees.

The estimate and the reference are paired by index: pose i of one is compared with pose i of
the other. There is no timestamp association here (evo's ``sync.associate_trajectories``): the
caller pairs the poses first. Written from evo's definitions (docs/metrics.md), not its code.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.spatial.transform import Rotation

from pcmapq.core.errors import EvaluationError
from pcmapq.core.stats import Stats
from pcmapq.core.words import count

Relation = Literal["translation_part", "rotation_angle_deg", "full"]
DeltaUnit = Literal["frames", "metres"]

#: The unit of each relation's errors ("" for the dimensionless full transformation).
UNITS: dict[str, str] = {"translation_part": "m", "rotation_angle_deg": "deg", "full": ""}


@dataclass(frozen=True)
class Alignment:
    """What was done to the estimate before comparing: its translations scaled by ``scale``,
    then every pose left-multiplied by [rotation, translation] (metres). Identity: none."""

    rotation: np.ndarray
    translation: np.ndarray
    scale: float = 1.0

    def matrix(self) -> np.ndarray:
        """The Sim(3) matrix [s R, t; 0, 1] (4, 4) that maps the estimate's positions onto the
        aligned ones: evo's ``alignment_transformation_sim3``, except that for a scale
        correction alone evo reports the fitted rotation and translation it does not apply."""
        m = np.eye(4)
        m[:3, :3] = self.scale * self.rotation
        m[:3, 3] = self.translation
        return m


NO_ALIGNMENT = Alignment(np.eye(3), np.zeros(3))


@dataclass(frozen=True)
class PoseErrors:
    """Per-pose (APE) or per-pair (RPE) errors, in ``unit``, with their statistics.

    ``pairs`` (M, 2) are the compared indices: (i, i) for APE, (i, j) for RPE. ``sse`` is the
    sum of squared errors (evo's seventh statistic; None when there is no error)."""

    errors: np.ndarray
    pairs: np.ndarray
    unit: str
    stats: Stats
    sse: float | None
    alignment: Alignment

    def statistics(self) -> dict[str, float | None]:
        """evo's ``get_all_statistics``: rmse, mean, median, std (population), min, max, sse."""
        s = self.stats
        return {"rmse": s.rmse, "mean": s.mean, "median": s.median, "std": s.std,
                "min": s.min, "max": s.max, "sse": self.sse}


def _poses(poses: np.ndarray, name: str) -> np.ndarray:
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] != (4, 4):
        raise ValueError(f"{name}: poses must be (N, 4, 4), got {p.shape}")
    return p


def _pair(est: np.ndarray, ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    est, ref = _poses(est, "estimate"), _poses(ref, "reference")
    if len(est) != len(ref):
        raise ValueError(f"estimate has {count(len(est), 'pose')}, reference {len(ref)}: "
                         "they are compared by index and must be as many")
    return est, ref


def inverse(poses: np.ndarray) -> np.ndarray:
    """The inverses of SE(3) poses (N, 4, 4): [R^T, -R^T t]."""
    rt = np.swapaxes(poses[:, :3, :3], 1, 2)
    out = np.zeros_like(poses)
    out[:, :3, :3] = rt
    out[:, :3, 3] = -np.einsum("nij,nj->ni", rt, poses[:, :3, 3])
    out[:, 3, 3] = 1.0
    return out


def align_umeyama(est_xyz: np.ndarray, ref_xyz: np.ndarray,
                  with_scale: bool) -> tuple[np.ndarray, np.ndarray, float]:
    """Umeyama (1991) least squares: (R (3, 3), t (3,) m, s) minimising
    sum |ref - (s R est + t)|^2 over points (N, 3); s = 1 unless ``with_scale``.

    Raises EvaluationError when the points' covariance has rank below 2 (evo refuses too)."""
    x = np.asarray(est_xyz, dtype=np.float64)
    y = np.asarray(ref_xyz, dtype=np.float64)
    if x.shape != y.shape or x.ndim != 2:
        raise ValueError(f"point sets must have the same (N, m) shape: {x.shape}, {y.shape}")
    n, m = x.shape
    if n == 0:
        raise EvaluationError("no poses to align")
    mx, my = x.mean(axis=0), y.mean(axis=0)
    xc, yc = x - mx, y - my
    var_x = float(np.sum(xc**2)) / n
    cov = yc.T @ xc / n
    u, d, vt = np.linalg.svd(cov)
    if np.count_nonzero(d > np.finfo(d.dtype).eps) < m - 1:
        raise EvaluationError(f"degenerate trajectory (its {count(n, 'position')} span less than a "
                              "plane): Umeyama alignment is not possible")
    sign = np.ones(m)
    if np.linalg.det(u) * np.linalg.det(vt) < 0.0:
        sign[-1] = -1.0
    r = (u * sign) @ vt
    s = float(np.sum(d * sign)) / var_x if with_scale else 1.0
    t = my - s * (r @ mx)
    return r, t, s


def align_estimate(est: np.ndarray, ref: np.ndarray, align: bool = False,
                   correct_scale: bool = False, align_origin: bool = False,
                   n_to_align: int | None = None) -> tuple[np.ndarray, Alignment]:
    """The estimate (N, 4, 4) moved as evo_ape/evo_rpe move it, and the move.

    ``align``: SE(3) Umeyama on the positions; with ``correct_scale`` Sim(3) (the translations
    scaled, then moved); ``correct_scale`` alone: the translations scaled only.
    ``align_origin``: the first pose put on the reference's first pose. ``n_to_align``: only
    the first n poses fit the alignment (all when None)."""
    est, ref = _pair(est, ref)
    if align and align_origin:
        raise ValueError("align and align_origin can't be used together")
    if align or correct_scale:
        k = len(est) if n_to_align is None else int(n_to_align)
        r, t, s = align_umeyama(est[:k, :3, 3], ref[:k, :3, 3], correct_scale)
        if not align:
            r, t = np.eye(3), np.zeros(3)
        a = Alignment(r, t, s)
    elif align_origin:
        if len(est) == 0:
            raise EvaluationError("no poses to align")
        to_origin = ref[0] @ inverse(est[:1])[0]
        a = Alignment(to_origin[:3, :3], to_origin[:3, 3])
    else:
        return est, NO_ALIGNMENT
    out = est.copy()
    out[:, :3, 3] *= a.scale
    out[:, :3, :] = np.einsum("ij,njk->nik", a.rotation, out[:, :3, :])
    out[:, :3, 3] += a.translation
    return out, a


def _relation(e: np.ndarray, relation: str) -> np.ndarray:
    """The error of each error pose E (K, 4, 4) under ``relation``."""
    if relation == "translation_part":
        return np.linalg.norm(e[:, :3, 3], axis=1)
    if relation == "rotation_angle_deg":
        if len(e) == 0:
            return np.zeros(0)
        return np.degrees(np.linalg.norm(Rotation.from_matrix(e[:, :3, :3]).as_rotvec(),
                                         axis=1))
    if relation == "full":
        return np.linalg.norm((e - np.eye(4)).reshape(len(e), 16), axis=1)
    raise ValueError(f"unknown relation {relation!r}: one of {', '.join(UNITS)}")


def _result(err: np.ndarray, pairs: np.ndarray, relation: str, a: Alignment) -> PoseErrors:
    sse = float(np.sum(err**2)) if len(err) else None
    return PoseErrors(err, pairs, UNITS[relation], Stats.of(err), sse, a)


def ape(est: np.ndarray, ref: np.ndarray, relation: Relation = "translation_part",
        align: bool = False, correct_scale: bool = False, align_origin: bool = False,
        n_to_align: int | None = None) -> PoseErrors:
    """Absolute pose error per pose, as evo_ape: E_i = est_i^-1 ref_i after the alignment
    (:func:`align_estimate`); "translation_part" is |est_i position - ref_i position| (m),
    "rotation_angle_deg" the angle of E_i's rotation (deg), "full" |E_i - I| (Frobenius)."""
    est, a = align_estimate(est, ref, align, correct_scale, align_origin, n_to_align)
    if relation == "translation_part":
        err = np.linalg.norm(est[:, :3, 3] - ref[:, :3, 3], axis=1)
    else:
        err = _relation(inverse(est) @ ref, relation)
    ids = np.arange(len(est))
    return _result(err, np.stack([ids, ids], axis=1), relation, a)


def pairs_by_frames(n: int, delta: int, all_pairs: bool = False) -> np.ndarray:
    """evo's pairs delta frames apart among n poses (M, 2): (0, d), (d, 2d), ... or, with
    ``all_pairs``, every (i, i + d)."""
    if delta < 1:
        raise ValueError(f"delta must be a positive number of frames, got {delta}")
    if all_pairs:
        i = np.arange(max(n - delta, 0))
        return np.stack([i, i + delta], axis=1)
    ids = np.arange(0, n, delta)
    return np.stack([ids[:-1], ids[1:]], axis=1)


def path_lengths(xyz: np.ndarray) -> np.ndarray:
    """The path length travelled to each position (N,) from the first, metres."""
    steps = np.linalg.norm(xyz[:-1] - xyz[1:], axis=1)
    return np.concatenate([np.zeros(1), np.cumsum(steps)])


def pairs_by_path(xyz: np.ndarray, delta: float, tol: float = 0.0,
                  all_pairs: bool = False) -> np.ndarray:
    """evo's pairs about ``delta`` metres of path apart (M, 2) along positions (N, 3).

    Consecutive: from pose 0, the next pose is the first at which the path since the previous
    one reaches ``delta``. ``all_pairs``: each i with the j > i whose path from i is nearest
    ``delta`` (the first on ties), kept when within ``tol`` metres of it."""
    if delta <= 0:
        raise ValueError(f"delta must be a positive length in metres, got {delta}")
    xyz = np.asarray(xyz, dtype=np.float64)
    n = len(xyz)
    if n < 2:
        return np.zeros((0, 2), dtype=int)
    cum = path_lengths(xyz)
    if all_pairs:
        return _all_pairs_by_path(cum, delta, tol)
    # step_to[k]: the length of the step to pose k, summed from each start as evo sums it.
    step_to = np.concatenate([np.zeros(1), np.linalg.norm(xyz[1:] - xyz[:-1], axis=1)])
    ids = [0]
    while True:
        a = ids[-1]
        # The first j whose path from a reaches delta, found on the cumulative lengths and
        # checked on the running sum from a (evo's order of additions, so ties fall alike).
        hi = min(int(np.searchsorted(cum, cum[a] + delta)) + 2, n)
        hit = np.zeros(0, dtype=int)
        while hi <= n:
            hit = np.flatnonzero(np.cumsum(step_to[a + 1:hi]) >= delta)
            if hit.size or hi == n:
                break
            hi = min(n, hi + max(hi - a, 2))
        if not hit.size:
            break
        ids.append(a + 1 + int(hit[0]))
    ids_a = np.asarray(ids)
    return np.stack([ids_a[:-1], ids_a[1:]], axis=1)


def _all_pairs_by_path(cum: np.ndarray, delta: float, tol: float) -> np.ndarray:
    n = len(cum)
    i = np.arange(n - 1)
    k = np.searchsorted(cum, cum[i] + delta)
    # |path(i, j) - delta| falls then rises with j: its minimum is next to k. A run of equal
    # lengths (a halt) counts from its first pose, as argmin takes the first.
    cand = np.clip(k[:, None] + np.arange(-2, 2)[None, :], i[:, None] + 1, n - 1)
    cand = np.maximum(np.searchsorted(cum, cum[cand]), i[:, None] + 1)
    err = np.abs((cum[cand] - cum[i][:, None]) - delta)
    best = err.min(axis=1)
    j = np.where(err == best[:, None], cand, n).min(axis=1)
    keep = best <= tol
    return np.stack([i[keep], j[keep]], axis=1)


def rpe(est: np.ndarray, ref: np.ndarray, delta: float = 1, delta_unit: DeltaUnit = "frames",
        relation: Relation = "translation_part", all_pairs: bool = False,
        rel_delta_tol: float = 0.1, pairs_from_reference: bool = False, align: bool = False,
        correct_scale: bool = False, align_origin: bool = False,
        n_to_align: int | None = None) -> PoseErrors:
    """Relative pose error per pair (i, j), as evo_rpe: E = (ref_i^-1 ref_j)^-1 (est_i^-1 est_j)
    after the alignment (:func:`align_estimate`; only a scale changes RPE), under ``relation``:
    "translation_part" |E's translation| (m), "rotation_angle_deg" E's rotation angle (deg),
    "full" |E - I|. Pairs are ``delta`` frames or metres apart (:func:`pairs_by_frames`,
    :func:`pairs_by_path`, tolerance ``rel_delta_tol`` * delta), taken along the (aligned)
    estimate unless ``pairs_from_reference``. No pair gives no error (evo raises instead)."""
    est, a = align_estimate(est, ref, align, correct_scale, align_origin, n_to_align)
    if delta_unit == "frames":
        if float(delta) != int(delta):
            raise ValueError(f"delta must be an integer number of frames, got {delta}")
        pairs = pairs_by_frames(len(est), int(delta), all_pairs)
    elif delta_unit == "metres":
        path = (ref if pairs_from_reference else est)[:, :3, 3]
        pairs = pairs_by_path(path, float(delta), float(delta) * rel_delta_tol, all_pairs)
    else:
        raise ValueError(f"unknown delta unit {delta_unit!r}: frames or metres")
    i, j = pairs[:, 0], pairs[:, 1]
    ref_rel = inverse(ref[i]) @ ref[j]
    est_rel = inverse(est[i]) @ est[j]
    err = _relation(inverse(ref_rel) @ est_rel, relation)
    return _result(err, pairs, relation, a)
