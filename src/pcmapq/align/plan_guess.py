"""A 3D guess from two levelled clouds' plans: the second opinion of the global 3D search.

FPFH features can all look alike where a place repeats itself (a town of similar blocks, a
corridor of equal doors): too few of their matches are right for RANSAC to find the pose, and it
returns a wrong one, even an upside-down one. Two LiDAR maps of one place, each levelled on its
floor, differ by a turn about the vertical, a shift and a floor height, and their plans are what
pcmapq's 2D global search (:func:`pcmapq.align.align`) places without a guess.

Frames: each cloud's levelling takes it to its plan frame, ``p_plan = R p`` (x, y in the plan,
z from its floor ``floor_z_m``); the 2D alignment takes the map's plan to the truth's; the result
``T`` (4x4) takes map points to the truth frame, ``p_truth = T @ p_map``; metres.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pcmapq.align.params import AlignParams
from pcmapq.core.frames import Levelling

if TYPE_CHECKING:
    from pcmapq.align.planar import RigidTarget

__all__ = ["guess_from_plans"]


def guess_from_plans(map_xy: np.ndarray, map_level: Levelling, truth_xy: np.ndarray,
                     truth_level: Levelling, params: AlignParams,
                     target: RigidTarget | None = None) -> np.ndarray:
    """4x4 map -> truth transform from the two plans' points (N, 2) and (M, 2), metres, each in
    its own levelled frame: the rigid 2D alignment (global search, then ICP; ``target``: the
    truth's points prepared for it), lifted to 3D with the two floors put on one height."""
    from pcmapq.align.planar import align  # SciPy, Numba: loaded when it runs

    plan = align(map_xy, truth_xy, params, target=target).transform
    lift = np.eye(4)
    lift[:2, :2] = plan.matrix[:2, :2]
    lift[:2, 3] = plan.matrix[:2, 2]
    lift[2, 3] = truth_level.floor_z_m - map_level.floor_z_m
    return _rotation(truth_level).T @ lift @ _rotation(map_level)


def _rotation(level: Levelling) -> np.ndarray:
    """The levelling's rotation as a 4x4 transform."""
    out = np.eye(4)
    out[:3, :3] = level.rotation
    return out
