"""SIFT's scale space: extrema where a blob is, and the same built in strips as whole."""

from __future__ import annotations

from dataclasses import fields

import cv2
import numpy as np
import pytest

from pcmapq.features import scale_space
from pcmapq.features.scale_space import extrema, octave_count
from pcmapq.features.sift import entropy
from pcmapq.features.walls import wall_image
from testkit import synth

SIGMA, LAYERS = 1.6, 3


def test_a_blob_is_found_where_it_is_at_its_size():
    v, u = np.mgrid[0:120, 0:140]
    blob_sigma = 4.0
    image = np.exp(-((u - 70.0) ** 2 + (v - 52.0) ** 2) / (2 * blob_sigma ** 2)).astype(np.float32)
    kp = extrema(image, SIGMA, LAYERS, octave_count(image.shape, SIGMA, LAYERS, 40.0), 0.01)
    strongest = np.argmax(np.abs(kp.contrast))
    np.testing.assert_allclose(kp.pt[strongest], (70.0, 52.0), atol=0.5)
    # a Gaussian blob of sigma s answers most at DoG scale s: size is twice the scale
    assert kp.size[strongest] == pytest.approx(2 * blob_sigma, rel=0.25)
    assert kp.contrast[strongest] < 0  # a bright blob is a minimum of the DoG


def blobs(shape: tuple[int, int]) -> np.ndarray:
    """float32 image of bright and dark Gaussian blobs of 2 to 8 pixels at random places."""
    rng = np.random.default_rng(0)
    image = np.zeros(shape, np.float32)
    for sigma in (2.0, 3.0, 5.0, 8.0):
        dots = np.zeros(shape, np.float32)
        n = int(image.size / (6 * sigma) ** 2)
        at = rng.integers(0, shape[0], n), rng.integers(0, shape[1], n)
        dots[at] = rng.choice([-1.0, 1.0], n) * sigma * sigma
        image += cv2.GaussianBlur(dots, (0, 0), sigma)
    return image


@pytest.mark.parametrize("kind", ["plan", "blobs"])
def test_strips_give_the_whole_octaves_extrema(monkeypatch, kind):
    if kind == "plan":  # what SIFT sees of a building: mostly empty between the walls
        plan = synth.building_plan(3)
        grid = synth.plan_grid(plan, 0.05)
        walls = wall_image(synth.render(plan, grid) == synth.OCCUPIED, grid)
        image = entropy(walls.image, 3.0)
    else:  # blobs everywhere: a strip short of its blurs' reach differs at its cuts
        image = blobs((330, 250))
    octaves = octave_count(image.shape, SIGMA, LAYERS, 20.0)
    assert octaves >= 2 and image.shape[0] > 300
    whole = extrema(image, SIGMA, LAYERS, octaves, 0.001)
    # one cell a layer: every octave in strips of twice its blurs' reach, cut several times
    monkeypatch.setattr(scale_space, "STACK_CELLS", 1)
    strips = extrema(image, SIGMA, LAYERS, octaves, 0.001)
    assert len(whole) > 100 and set(whole.octave) == set(range(octaves))
    for field in fields(whole):
        a, b = getattr(whole, field.name), getattr(strips, field.name)
        assert a.dtype == b.dtype and np.array_equal(a, b), field.name
