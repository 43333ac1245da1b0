"""The centre lines' band: drawn from the line's cells, it is the shading of a whole-raster
distance transform cell for cell (any width, lines at the raster's edge, cores under it), and a
known answer."""

from __future__ import annotations

import cv2
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pcmapq.core.morphology import distance_to
from pcmapq.features.band import draw_band


def shaded_distance(line: np.ndarray, half_width: float, under: np.ndarray) -> np.ndarray:
    """The band as a distance transform of the whole raster shades it."""
    band = under.copy()
    if line.any():
        shade = distance_to(line)
        np.subtract(half_width, shade, out=shade)
        np.add(0.5, shade, out=shade)
        np.maximum(band, np.clip(shade, 0.0, 1.0, out=shade), out=band)
    return band


@given(st.lists(st.tuples(st.integers(-5, 84), st.integers(-5, 64), st.integers(-5, 84),
                          st.integers(-5, 64)), min_size=0, max_size=6),
       st.sampled_from([0.5, 1.0, 1.5, 2.5, 3.0, 0.5 * 0.15 / 0.025, 4.2, 5.5]),
       st.integers(0, 2**32 - 1))
@settings(max_examples=80, deadline=None)
def test_the_band_is_a_shaded_distance_transform(segments, half_width, seed):
    """Half widths up to 5.5 cells (module docstring), lines crossing the raster's edge."""
    line = np.zeros((60, 80), np.uint8)
    for x0, y0, x1, y1 in segments:
        cv2.line(line, (x0, y0), (x1, y1), 1, 1)
    under = (np.random.default_rng(seed).random(line.shape) < 0.01).astype(np.float32)
    want = shaded_distance(line.astype(bool), half_width, under)
    got = draw_band(line.astype(bool), half_width, under.copy())
    assert got.dtype == np.float32
    assert np.array_equal(got, want)


def test_a_line_three_cells_wide_each_side():
    """A horizontal line, half width 3: full shade within 2 cells, half at 3, none at 4."""
    line = np.zeros((21, 30), bool)
    line[10, 5:25] = True
    band = draw_band(line, 3.0, np.zeros(line.shape, np.float32))
    column = band[:, 15]
    assert np.array_equal(column[8:13], np.ones(5, np.float32))
    assert column[7] == column[13] == 0.5
    assert not column[:7].any() and not column[14:].any()
