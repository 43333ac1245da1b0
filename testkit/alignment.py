"""The alignment tests' plan (:func:`testkit.synth.building_plan`, seed 0), as truth points and
as a noisy scan, and the part of a map inside a box."""

from __future__ import annotations

import numpy as np

from testkit import synth

#: The plan of the alignment tests and its size, metres.
PLAN = synth.building_plan(0)
WIDTH, HEIGHT = 24.0, 16.0


def plan_truth() -> np.ndarray:
    """The plan's walls as points 5 cm apart, plan frame, metres."""
    return synth.wall_points(PLAN, spacing=0.05)


def plan_scan() -> np.ndarray:
    """The same walls sampled again with 1.5 cm noise, in the plan frame."""
    return synth.wall_points(PLAN, spacing=0.05, noise=0.015, seed=1)


def inside(points: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray:
    """The points (N, 2+) within the box (x0, y0, x1, y1), metres."""
    x0, y0, x1, y1 = box
    keep = (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)
    return points[keep]
