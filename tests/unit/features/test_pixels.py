"""Graphs over the set pixels of a sparse image, against full-image OpenCV results."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from pcmapq.features.pixels import flat_index, neighbour_pairs, pieces


def _mask(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.random((60, 45)) < 0.3


@pytest.mark.parametrize("seed", range(4))
def test_neighbour_pairs_are_the_8_neighbours(seed):
    mask = _mask(seed)
    v, u, index = flat_index(mask)
    a, b = neighbour_pairs(index, mask.shape[1])
    got = set(zip(index[a].tolist(), index[b].tolist(), strict=True))
    cols = mask.shape[1]
    want = {(p, q) for p in index.tolist() for q in index.tolist()
            if p < q and abs(p // cols - q // cols) <= 1 and abs(p % cols - q % cols) <= 1}
    assert got == want and len(a) == len(want)


@pytest.mark.parametrize("seed", range(4))
def test_pieces_are_opencv_components(seed):
    mask = _mask(seed)
    v, u, index = flat_index(mask)
    n, label = pieces(len(index), *neighbour_pairs(index, mask.shape[1]))
    count, image = cv2.connectedComponents(mask.astype(np.uint8), connectivity=8)
    assert n == count - 1
    pairs = set(zip(label.tolist(), image[v, u].tolist(), strict=True))
    assert len(pairs) == n  # the same partition
    first = np.unique(label, return_index=True)[1]
    assert np.all(np.diff(first) > 0)  # numbered by first pixel


def test_empty():
    v, u, index = flat_index(np.zeros((5, 5), bool))
    a, b = neighbour_pairs(index, 5)
    assert len(a) == len(b) == 0 and pieces(0, a, b)[0] == 0
