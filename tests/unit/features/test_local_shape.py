"""Each point's normal and surface variation (pcmapq.features.local_shape): the least eigenpair of
its neighbours' covariance, as LAPACK gives it, on planes, lines, blobs and repeated points."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.features.local_shape import _covariances, _least, normals_and_variation

pytestmark = pytest.mark.unit


def neighbourhoods(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Points and 12-point neighbourhoods of every shape: tilted planes with noise (flat),
    discs that are nearly round, lines (two least eigenvalues alike), blobs (all alike), and
    one point repeated (no spread at all)."""
    groups = []
    for _ in range(400):
        normal = rng.normal(size=3)
        normal /= np.linalg.norm(normal)
        u = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        v = np.cross(normal, u)
        a, b = rng.uniform(-0.2, 0.2, size=(2, 12))
        groups.append(rng.uniform(-50, 50, 3) + a[:, None] * u + b[:, None] * v
                      + rng.normal(scale=rng.choice([0.0, 1e-3, 1e-2]), size=(12, 1)) * normal)
    for _ in range(100):
        direction = rng.normal(size=3)
        groups.append(rng.uniform(-50, 50, 3) + rng.uniform(-1, 1, (12, 1)) * direction
                      + rng.normal(scale=1e-4, size=(12, 3)))
    groups += [rng.normal(size=(12, 3)) for _ in range(100)]
    groups.append(np.tile([3.0, -2.0, 1.0], (12, 1)))
    points = np.vstack(groups)
    return points, np.arange(len(points)).reshape(-1, 12)


def test_the_normals_and_variations_are_lapacks():
    points, near = neighbourhoods(np.random.default_rng(0))
    values, vectors = np.linalg.eigh(_covariances(points, near))
    normal, variation = normals_and_variation(points, near)
    sine = np.linalg.norm(np.cross(normal, vectors[:, :, 0]), axis=1)
    assert sine.max() < 1e-12
    np.testing.assert_allclose(np.linalg.norm(normal, axis=1), 1.0, atol=1e-14)
    expected = values[:, 0] / np.maximum(values.sum(axis=1), 1e-18)
    np.testing.assert_allclose(variation, expected, rtol=0, atol=1e-14)


def test_the_planes_normals_are_their_own():
    """A neighbourhood on a plane of known normal, without noise: that normal, variation 0."""
    rng = np.random.default_rng(1)
    normal = np.array([0.3, -0.4, 0.866])
    normal /= np.linalg.norm(normal)
    u = np.cross(normal, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    a, b = rng.uniform(-1, 1, size=(2, 20))
    points = 10.0 + a[:, None] * u + b[:, None] * v
    found, variation = normals_and_variation(points, np.arange(20)[None, :])
    assert abs(abs(found[0] @ normal) - 1.0) < 1e-12
    assert abs(variation[0]) < 1e-12


def test_lines_and_repeated_points_are_left_to_lapack():
    """Where the least eigenvector is barely defined (a line's two least eigenvalues alike) or
    not at all (no spread), LAPACK's is taken."""
    points, near = neighbourhoods(np.random.default_rng(2))
    odd = np.empty(len(near), np.int64)
    count = _least(points, near, np.empty((len(near), 3)), np.empty(len(near)), odd)
    left = set(odd[:count].tolist())
    assert set(range(400, 500)) | {len(near) - 1} <= left  # the lines, the repeated point
    assert len(left & set(range(400))) < 40  # most planes in closed form
