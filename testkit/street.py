"""A synthetic street as a 3D LiDAR map sees it, with known geometry: a ground plane, a facade
on each side with doorways set back at uneven spacing, and poles along both kerbs, so that every
stretch of it pins a registration in all six degrees of freedom. Metres, z up; the street runs
along x."""

from __future__ import annotations

import numpy as np

#: The street's half width (kerb to facade), facade height and pole height, metres.
HALF_WIDTH, FACADE_HEIGHT, POLE_HEIGHT = 6.0, 6.0, 4.0


def _grid(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Every (u, v) pair of two 1D arrays, (len(u) * len(v), 2)."""
    return np.stack(np.meshgrid(u, v, indexing="ij"), axis=-1).reshape(-1, 2)


def street(x0: float = 0.0, x1: float = 40.0, spacing: float = 0.1, noise: float = 0.005,
           seed: int = 0) -> np.ndarray:
    """The street from ``x0`` to ``x1`` (N, 3), points ``spacing`` apart with Gaussian noise of
    std ``noise``; ``seed`` draws where the doorways and poles stand (the same seed, the same
    street) and the noise."""
    layout = np.random.default_rng(seed)
    ground = _grid(np.arange(x0, x1, spacing), np.arange(-HALF_WIDTH, HALF_WIDTH, spacing))
    parts = [np.column_stack([ground, np.zeros(len(ground))])]
    heights = np.arange(0.0, FACADE_HEIGHT, spacing)
    for side in (-1.0, 1.0):
        face = _grid(np.arange(x0, x1, spacing), heights)
        parts.append(np.column_stack([face[:, 0], np.full(len(face), side * HALF_WIDTH),
                                      face[:, 1]]))
        # doorways: 1.5 m wide, 0.6 m deep recesses, 3 to 7 m apart
        starts = x0 + np.cumsum(layout.uniform(3.0, 7.0, int((x1 - x0) / 3) + 1))
        for start in starts[starts < x1 - 1.5]:
            for edge in (start, start + 1.5):
                jamb = _grid(np.arange(0.0, 0.6, spacing), np.arange(0.0, 2.4, spacing))
                parts.append(np.column_stack([np.full(len(jamb), edge),
                                              side * (HALF_WIDTH + jamb[:, 0]), jamb[:, 1]]))
        # poles: 0.15 m radius, 2 to 6 m apart, 1 m in from the facade
        poles = x0 + np.cumsum(layout.uniform(2.0, 6.0, int((x1 - x0) / 2) + 1))
        turns = np.arange(0.0, 2 * np.pi, spacing / 0.15)
        ring = 0.15 * np.column_stack([np.cos(turns), np.sin(turns)])
        for x in poles[poles < x1]:
            shell = _grid(np.arange(len(ring)), np.arange(0.0, POLE_HEIGHT, spacing))
            centre = np.array([x, side * (HALF_WIDTH - 1.0)])
            parts.append(np.column_stack([ring[shell[:, 0].astype(int)] + centre, shell[:, 1]]))
    cloud = np.vstack(parts)
    return cloud + np.random.default_rng(seed + 1).normal(0.0, noise, cloud.shape)


def sunk(cloud: np.ndarray, beyond_x: float, depth: float) -> np.ndarray:
    """``cloud`` (N, 3) with its points beyond ``x = beyond_x`` lowered by ``depth`` metres."""
    out = cloud.copy()
    out[out[:, 0] > beyond_x, 2] -= depth
    return out


def tilted(cloud: np.ndarray, degrees_per_metre: float) -> np.ndarray:
    """``cloud`` (N, 3) bent down along x as a drifting pitch bends a map: the pitch grows by
    ``degrees_per_metre`` per metre of x from x = 0, so a point at x is lowered by
    ``tan(rate) x^2 / 2``, metres, its slope there the pitch."""
    out = cloud.copy()
    x = np.maximum(out[:, 0], 0.0)
    out[:, 2] -= np.tan(np.radians(degrees_per_metre)) * x**2 / 2
    return out


def street_run(cloud: np.ndarray, scans: int, step: float = 1.0, reach: float = 8.0,
               start: float = 0.0) -> tuple[list[np.ndarray], np.ndarray]:
    """A car's run along the street ``cloud`` (N, 3): scan k taken at x = ``start`` + k *
    ``step``, 1.5 m above the ground, holding the street's points within ``reach`` metres of
    it. The scans' points in the scanner's frame (each (n, 3)) and the scanner's poses (K, 4,
    4, scanner -> street: a shift)."""
    poses = np.repeat(np.eye(4)[None], scans, axis=0)
    poses[:, 0, 3] = start + step * np.arange(scans)
    poses[:, 2, 3] = 1.5
    seen = [cloud[np.linalg.norm(cloud - pose[:3, 3], axis=1) <= reach] - pose[:3, 3]
            for pose in poses]
    return seen, poses
