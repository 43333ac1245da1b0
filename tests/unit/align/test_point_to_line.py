"""The point-to-line ICP's median of its residuals: numpy's, to the bit."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align.point_to_line import _median


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 8, 1000, 1001])
def test_median_is_numpys(n):
    rng = np.random.default_rng(n)
    for scale in (1e-3, 1.0, 1e3):
        values = np.abs(rng.normal(size=n)) * scale
        assert _median(values) == float(np.median(values))
    assert _median(np.zeros(n)) == 0.0

