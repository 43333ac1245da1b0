"""The rooms' seeds: pcmapq's h-maxima and grayscale reconstruction give scikit-image's cells
exactly (plateaus, smooth ridges, edges, any size), and a known answer."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from skimage.morphology import h_maxima as skimage_h_maxima
from skimage.morphology import reconstruction as skimage_reconstruction

from pcmapq.features.peaks import h_maxima, reconstruction

pytestmark = pytest.mark.unit


def image(seed: int, rows: int, cols: int, kind: int) -> np.ndarray:
    """float32 test images: noise, noise in four levels (plateaus), or noise blurred (ridges)."""
    values = np.random.default_rng(seed).random((rows, cols)).astype(np.float32)
    if kind == 1:
        return np.round(values * 4).astype(np.float32) / np.float32(4)
    if kind == 2:
        return cv2.GaussianBlur(values, (0, 0), 2.0)
    return values


@given(st.integers(0, 10_000), st.integers(1, 40), st.integers(1, 40), st.integers(0, 2),
       st.sampled_from([0.05, 0.1, 0.2, 0.5]))
@settings(max_examples=150, deadline=None)
def test_reconstruction_and_h_maxima_are_scikit_images(seed, rows, cols, kind, h):
    img = image(seed, rows, cols, kind)
    rebuilt = reconstruction(img - np.float32(h), img)
    want = skimage_reconstruction(img - np.float32(h), img)
    assert rebuilt.dtype == want.dtype and np.array_equal(rebuilt, want)
    assert np.array_equal(h_maxima(img, h), skimage_h_maxima(img, h))


def test_h_maxima_of_a_clearance_is_scikit_images():
    """A room plan's clearance (the rooms' own input), large enough for long propagations."""
    free = np.zeros((300, 400), np.uint8)
    cv2.rectangle(free, (10, 10), (190, 290), 1, -1)
    cv2.rectangle(free, (210, 10), (390, 140), 1, -1)
    cv2.rectangle(free, (210, 160), (390, 290), 1, -1)
    free[140:160, 290:310] = 1  # a door
    free[100:120, 190:210] = 1  # another
    clearance = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * np.float32(0.05)
    for h in (0.05, 0.2, 1.0):
        assert np.array_equal(h_maxima(clearance, h), skimage_h_maxima(clearance, h))


def test_a_peak_lower_than_h_above_its_pass_is_not_a_maximum():
    """Two peaks, 1.0 and 0.6, joined by a pass at 0.3: with h = 0.2 both are maxima, with
    h = 0.4 only the higher one (the lower rises 0.3 above the pass)."""
    profile = np.array([0.0, 0.5, 1.0, 0.5, 0.3, 0.45, 0.6, 0.45, 0.0], np.float32)
    img = np.tile(profile, (3, 1))
    img[[0, 2]] = 0.0
    assert np.flatnonzero(h_maxima(img, 0.2)[1]).tolist() == [2, 6]
    assert np.flatnonzero(h_maxima(img, 0.4)[1]).tolist() == [2]
    assert not h_maxima(img, 2.0).any()
