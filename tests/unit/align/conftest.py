"""The alignment tests' plan, as truth points and as a noisy scan."""

from __future__ import annotations

import numpy as np
import pytest

from testkit import synth

#: The plan of the alignment tests and its size, metres.
PLAN = synth.building_plan(0)
WIDTH, HEIGHT = 24.0, 16.0


@pytest.fixture(scope="module")
def truth() -> np.ndarray:
    """The plan's walls as points 5 cm apart, plan frame, metres."""
    return synth.wall_points(PLAN, spacing=0.05)


@pytest.fixture(scope="module")
def scan() -> np.ndarray:
    """The same walls sampled again with 1.5 cm noise, in the plan frame."""
    return synth.wall_points(PLAN, spacing=0.05, noise=0.015, seed=1)
