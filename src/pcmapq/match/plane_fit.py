"""The planes' own fit (:func:`plane_fit`): a small rigid motion of the map's planes onto the
truth's, fitted to the matched planes by a robust estimate after the 3D registration.

The registration fits the map to the truth as a whole, so a few structures that moved (a wall
moved, a floor raised) pull it a little and spread their change over every structure. This fit
rests on the planes that agree: each matched pair votes with the four corners of the map
plane's rectangle, their distances from the truth plane along its normal (metres) the
residuals; the motion is linearised about the planes' centre and solved by iteratively
reweighted least squares, first towards the least sum of each plane's RMS corner distance (an
L1 fit, which a few planes cannot pull; least squares below :data:`MIN_SCALE`), then with
Tukey's biweight (each plane's weight falls to 0 at :data:`TUKEY_C` robust deviations of those
distances, their median absolute deviation and at least :data:`MIN_SCALE`). A direction of the
motion (an eigenvector of the fit's normal matrix, rotations in radians times the corners' RMS
radius, so in metres alike) is corrected only when at least :data:`MIN_SUPPORT` planes' worth
of weight hold it (the inverse of the sum of the squared shares of the planes in it): a plane
alone in its direction (the one horizontal plane of a street) keeps the displacement the
registration gave it rather than being fitted to 0. The fit is applied only when it moves no
matched map plane's corner further than the distance within which the registration's last ICP
stage pairs points (its ``reach``): structures that moved can pull the registration no further
than that, and a larger motion (a map bent by drift, whose planes agree only in parts) would be
another registration, not a correction of this one. No random draw; metres, radians inside,
degrees out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.features.planes3d import Planes, oriented

#: Rounds towards the L1 fit, then rounds of Tukey's biweight, at most.
L1_ROUNDS, TUKEY_ROUNDS = 20, 10
#: Tukey's biweight: a plane's weight is 0 beyond this many robust deviations.
TUKEY_C = 4.685
#: The least robust deviation of the planes' distances, metres: a plane found at a 0.1 m voxel
#: is not fitted better than a few millimetres.
MIN_SCALE = 0.005
#: A direction of the motion is corrected when at least this many planes' worth hold it.
MIN_SUPPORT = 3.0
#: The Tukey rounds stop when a step (its rotation times the corners' radius, and its shift)
#: is below this, metres.
CONVERGED = 1e-9


@dataclass(frozen=True)
class PlaneFit:
    """The planes' own fit. fitted: the motion found (4x4, the registered map to the truth
    frame), applied or not; centre: (3,) the matched map planes' centre, metres; held: the
    matched planes of final weight at least 0.5, of ``pairs``; largest_move: how far the fit
    moves the farthest corner of a matched map plane, metres; reach: the most it may (None: no
    bound), metres."""

    fitted: np.ndarray
    centre: np.ndarray
    held: int
    pairs: int
    largest_move: float
    reach: float | None = None

    @property
    def applied(self) -> bool:
        """Whether the map's structures were moved by it: it moves no corner beyond reach."""
        return self.reach is None or self.largest_move <= self.reach

    @property
    def matrix(self) -> np.ndarray:
        """The motion the map's structures were moved by (4x4; the identity when not
        applied)."""
        return self.fitted if self.applied else np.eye(4)

    @property
    def offset(self) -> float:
        """How far the fit found moves the planes' centre, metres."""
        return float(np.linalg.norm(self.fitted[:3, :3] @ self.centre + self.fitted[:3, 3]
                                    - self.centre))

    @property
    def angle(self) -> float:
        """The rotation of the fit found, degrees."""
        r = self.fitted[:3, :3]
        sine = np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2
        return float(np.degrees(np.arctan2(sine, (np.trace(r) - 1) / 2)))


def rotation(omega: np.ndarray) -> np.ndarray:
    """The rotation (3x3) of the rotation vector ``omega`` (radians; Rodrigues)."""
    angle = float(np.linalg.norm(omega))
    if angle < 1e-15:
        return np.eye(3)
    k = omega / angle
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * cross + (1.0 - np.cos(angle)) * cross @ cross


def _step(rows: np.ndarray, residual: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """The weighted least-squares step (6,) of the linearised motion: ``rows`` (K, 4, 6) each
    corner's derivatives, ``residual`` (K, 4) metres, ``weight`` (K,); only along the
    directions at least :data:`MIN_SUPPORT` planes' worth hold (see the module)."""
    each = weight[:, None, None] * np.einsum("kci,kcj->kij", rows, rows)  # (K, 6, 6)
    normal = each.sum(axis=0)
    value, vector = np.linalg.eigh(normal)
    live = value > 1e-12 * max(float(value.max()), 1e-300)
    share = np.einsum("ia,kij,ja->ka", vector, each, vector) / np.where(live, value, 1.0)
    support = 1.0 / np.maximum(np.sum(share ** 2, axis=0), 1e-300)
    keep = live & (support >= MIN_SUPPORT)
    rhs = vector.T @ np.einsum("k,kci,kc->i", weight, rows, residual)
    return -vector[:, keep] @ (rhs[keep] / value[keep])


def plane_fit(truth: Planes, map_: Planes, truth_idx: np.ndarray, map_idx: np.ndarray,
              reach: float | None = None) -> PlaneFit:
    """The planes' own fit of the matched pairs (``truth_idx``, ``map_idx``; both sides'
    planes in the truth frame after the registration, metres), applied when it moves no
    matched map plane's corner more than ``reach`` metres (None: whatever it moves); see
    the module."""
    count = len(truth_idx)
    if count == 0:
        return PlaneFit(np.eye(4), np.zeros(3), 0, 0, 0.0, reach)
    normal, offset = truth.normal[truth_idx], truth.offset[truth_idx]
    corners = map_.corners[map_idx]  # (K, 4, 3)
    centre = corners.reshape(-1, 3).mean(axis=0)
    radius = max(float(np.sqrt(np.mean(np.sum((corners - centre) ** 2, axis=2)))), 1e-9)
    turn, shift = np.eye(3), np.zeros(3)
    weight = np.ones(count)
    for round_ in range(L1_ROUNDS + TUKEY_ROUNDS):
        at = (corners - centre) @ turn.T + centre + shift
        residual = np.einsum("kj,kcj->kc", normal, at) - offset[:, None]
        size = np.sqrt(np.mean(residual ** 2, axis=1))
        weight = _weights(size, round_ < L1_ROUNDS)
        arm = np.cross(at - centre, normal[:, None, :]) / radius
        rows = np.concatenate([arm, np.broadcast_to(normal[:, None, :], arm.shape)], axis=2)
        step = _step(rows, residual, weight)
        spin = rotation(step[:3] / radius)
        turn, shift = spin @ turn, spin @ shift + step[3:]
        if np.linalg.norm(step[:3]) + np.linalg.norm(step[3:]) < CONVERGED \
                and round_ >= L1_ROUNDS:
            break
    at = (corners - centre) @ turn.T + centre + shift
    size = np.sqrt(np.mean((np.einsum("kj,kcj->kc", normal, at) - offset[:, None]) ** 2, 1))
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = turn, centre + shift - turn @ centre
    move = float(np.linalg.norm(at - corners, axis=2).max())
    return PlaneFit(matrix, centre, int(np.count_nonzero(_weights(size, False) >= 0.5)),
                    count, move, reach)


def _weights(size: np.ndarray, l1: bool) -> np.ndarray:
    """Each plane's weight from its RMS corner distance ``size`` (metres): towards the L1 fit
    (relative: 1 / size, the largest 1), or Tukey's biweight."""
    if l1:
        inverse = 1.0 / np.maximum(size, MIN_SCALE)
        return inverse / inverse.max()
    scale = max(1.4826 * float(np.median(size)), MIN_SCALE)
    u = size / (TUKEY_C * scale)
    return np.where(u < 1.0, (1.0 - u ** 2) ** 2, 0.0)


def moved(planes: Planes, matrix: np.ndarray) -> Planes:
    """The planes moved by the rigid ``matrix`` (4x4), metres: normals turned (largest
    component positive), offsets, centroids and corners moved; extents and areas kept."""
    turn, shift = matrix[:3, :3], matrix[:3, 3]
    normal = oriented(planes.normal @ turn.T)
    centroid = planes.centroid @ turn.T + shift
    return Planes(normal, np.einsum("ij,ij->i", normal, centroid), centroid,
                  planes.corners @ turn.T + shift, planes.extent, planes.area, planes.points)
