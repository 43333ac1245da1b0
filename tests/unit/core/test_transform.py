"""Points through a homogeneous matrix: the numbers of the plain formula, in one array."""

from __future__ import annotations

import tracemalloc

import numpy as np

from pcmapq.core.transform import affine


def test_affine_gives_the_formulas_numbers_in_one_array():
    rng = np.random.default_rng(0)
    points = rng.uniform(-50.0, 50.0, (300_000, 3))
    matrix = np.eye(4)
    matrix[:3, :3] = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    matrix[:3, 3] = [1.5, -2.0, 0.25]
    expected = points @ np.ascontiguousarray(matrix[:3, :3].T) + matrix[:3, 3]
    tracemalloc.start()
    try:
        got = affine(points, matrix)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert np.array_equal(got, expected)
    assert peak < 1.5 * got.nbytes
