"""The alignment tests' plan, as truth points and as a noisy scan (testkit.alignment)."""

from __future__ import annotations

import numpy as np
import pytest

from testkit.alignment import plan_scan, plan_truth


@pytest.fixture(scope="module")
def truth() -> np.ndarray:
    """The plan's walls as points 5 cm apart, plan frame, metres."""
    return plan_truth()


@pytest.fixture(scope="module")
def scan() -> np.ndarray:
    """The same walls sampled again with 1.5 cm noise, in the plan frame."""
    return plan_scan()
