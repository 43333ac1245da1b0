"""A raster map bent as the points of synth.bend are: known answers."""

from __future__ import annotations

import numpy as np

from testkit import synth

FILL = 127


def test_a_bent_image_puts_each_pixel_where_bend_puts_its_point():
    """Single occupied pixels in a box (x right, y up from its lower-left pixel), bent so the
    far corner moves by 5 % of the diagonal: each lands within a pixel of synth.bend's point,
    and the lower-left corner stays."""
    image = np.full((220, 300), FILL, np.uint8)
    image[20:201, 30:271] = 255  # the known box: corners (30, 200) and (270, 20), col/row
    marks = np.array([[30, 200], [270, 200], [270, 20], [30, 20], [150, 110], [200, 60]])
    image[marks[:, 1], marks[:, 0]] = 0
    bent = synth.bend_image(image, 0.05, FILL)

    box = np.column_stack([marks[:, 0] - 30.0, 200.0 - marks[:, 1]])  # x right, y up
    width, diagonal = 240.0, np.hypot(240.0, 180.0)
    rate = np.degrees(2.0 * np.arcsin(0.05 / 2.0)) / width
    moved = synth.bend(box, rate)
    np.testing.assert_allclose(np.hypot(*(moved[2] - box[2])), 0.05 * diagonal, rtol=1e-9)
    found = np.argwhere(bent == 0)  # row, col
    for x, y in moved:
        col, row = 30.0 + x, 200.0 - y
        assert np.min(np.hypot(found[:, 1] - col, found[:, 0] - row)) <= 1.0
    assert len(found) == len(marks)
    assert bent[200, 30] == 0 and image[200, 30] == 0


def test_no_bend_is_the_image():
    image = np.full((50, 60), FILL, np.uint8)
    image[10:40, 5:50] = 255
    image[20, 10:45] = 0
    assert np.array_equal(synth.bend_image(image, 0.0, FILL), image)
