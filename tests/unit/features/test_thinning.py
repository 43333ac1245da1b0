"""The walls' thinning: pcmapq's Zhang-Suen thinning gives scikit-image's skeleton cell for cell
(walls of any thickness, noise, solid blocks, cells on the image's edge), and a known answer."""

from __future__ import annotations

import cv2
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from skimage.morphology import skeletonize as skimage_skeletonize

from pcmapq.features.thinning import skeletonize


@given(st.lists(st.tuples(st.integers(0, 119), st.integers(0, 119), st.integers(0, 119),
                          st.integers(0, 119), st.integers(1, 9)), min_size=1, max_size=8))
@settings(max_examples=60, deadline=None)
def test_walls_of_any_thickness_thin_as_scikit_image(walls):
    """Lines 1-9 cells thick, crossing, touching the image's edges."""
    image = np.zeros((120, 120), np.uint8)
    for x0, y0, x1, y1, thickness in walls:
        cv2.line(image, (x0, y0), (x1, y1), 1, thickness)
    mask = image.astype(bool)
    assert np.array_equal(skeletonize(mask), skimage_skeletonize(mask))


@given(st.integers(1, 60), st.integers(1, 60), st.floats(0.05, 0.95), st.integers(0, 3),
       st.integers(0, 2**32 - 1))
@settings(max_examples=80, deadline=None)
def test_noise_and_blobs_thin_as_scikit_image(rows, cols, density, grow, seed):
    """Random cells, grown into blobs by 0-3 dilations: every neighbourhood the table holds."""
    mask = np.random.default_rng(seed).random((rows, cols)) < density
    if grow:
        mask = cv2.dilate(mask.view(np.uint8), np.ones((3, 3), np.uint8),
                          iterations=grow).view(bool)
    assert np.array_equal(skeletonize(mask), skimage_skeletonize(mask))


def test_walls_one_empty_line_apart_stay_apart():
    """Two bands one empty row (or column) apart thin to two lines each, not one between them."""
    mask = np.zeros((60, 70), bool)
    mask[10:14, 5:60] = True  # 4 rows thick
    mask[15:19, 5:60] = True  # one empty row between
    mask[30:50, 20:23] = True
    mask[30:50, 24:27] = True  # one empty column between
    thin = skeletonize(mask)
    assert np.array_equal(thin, skimage_skeletonize(mask))
    assert np.count_nonzero(thin[10:19].any(axis=1)) >= 2
    assert np.count_nonzero(thin[30:50, 20:27].any(axis=0)) >= 2


def test_a_band_thins_to_one_line_and_the_input_is_kept():
    """A band 5 cells thick and 40 long thins to a line along its middle row (a cell off it at
    an end); the mask passed in is not changed; nothing thins to nothing."""
    mask = np.zeros((20, 50), bool)
    mask[6:11, 5:45] = True
    before = mask.copy()
    thin = skeletonize(mask)
    assert np.array_equal(mask, before)
    assert thin.dtype == bool and thin.shape == mask.shape
    assert set(np.flatnonzero(thin.any(axis=1))) <= {7, 8, 9}
    assert thin[8, 8:42].all() and thin.sum() <= 40
    assert not skeletonize(np.zeros((5, 5), bool)).any()
    assert np.array_equal(skeletonize(np.ones((1, 1), bool)), np.ones((1, 1), bool))
