"""Raster morphology (pcmapq.core.morphology): blocks hollowed and walls kept by the outline;
the distance transform the same wherever its output lands."""

from __future__ import annotations

import cv2
import numpy as np

from pcmapq.core.morphology import distance_to, outline, precise_distance


def test_outline_hollows_blocks_and_keeps_walls():
    """A 9-cell block keeps a band 2 cells wide; a 4-cell wall stays whole; the image's
    border counts as outside."""
    mask = np.zeros((20, 20), bool)
    mask[2:11, 2:11] = True  # block
    mask[14:18, :] = True  # wall 4 cells thick, touching both sides of the image
    band = outline(mask, 2.0)
    assert band[14:18, :].all()
    assert band[2:4, 2:11].all() and band[2:11, 2:4].all()
    assert not band[4:9, 4:9].any()
    assert band.sum() == 81 - 25 + 80


def test_a_small_distance_field_is_the_same_wherever_memory_puts_it():
    """OpenCV's precise transform of an image under 2^14 cells (IPP's) changes in its last bit
    with its output's address modulo 32 bytes; pcmapq's is one field, call after call."""
    mask = np.zeros((60, 70), bool)
    mask[10, 20] = mask[45, 3] = True
    image = np.logical_not(mask).view(np.uint8)
    buffer = np.empty(mask.size + 16, np.float32)
    opencv = set()
    for start in range(8):  # OpenCV's own output, 4 bytes further each time
        out = buffer[start:start + mask.size].reshape(mask.shape)
        cv2.distanceTransform(image, cv2.DIST_L2, cv2.DIST_MASK_PRECISE, dst=out)
        opencv.add(out.tobytes())
    kept = [distance_to(mask) for _ in range(40)]  # all alive: each at another address
    assert len({field.tobytes() for field in kept}) == 1
    assert np.array_equal(precise_distance(image), kept[0])
    assert kept[0].tobytes() in opencv and kept[0][13, 24] == 5.0  # a 3-4-5 triangle
