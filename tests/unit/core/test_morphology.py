"""The outline of filled blocks (pcmapq.core.morphology): blocks hollowed, walls kept."""

from __future__ import annotations

import numpy as np

from pcmapq.core.morphology import outline


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
