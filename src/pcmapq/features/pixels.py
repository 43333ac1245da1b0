"""Graphs over the set pixels of a sparse binary image: its 8-neighbour pairs and connected
pieces, visiting only the set pixels (a wall's skeleton or ridge covers a few percent of a
large raster; a full-image pass per step costs more than the pixels it finds)."""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import connected_components


def flat_index(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The set pixels of ``mask`` (rows, cols) in raster order: rows v, columns u and flat
    indices ``v * cols + u`` (sorted), each (N,) int64."""
    v, u = np.nonzero(mask)
    v, u = v.astype(np.int64), u.astype(np.int64)
    return v, u, v * mask.shape[1] + u


def neighbour_pairs(index: np.ndarray, cols: int) -> tuple[np.ndarray, np.ndarray]:
    """Every pair of 8-neighbours among pixels given by sorted flat indices ``index`` of an
    image ``cols`` wide, once each: positions (a, b) into ``index``, b after a in raster
    order."""
    if len(index) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    u = index % cols
    found = []
    # the four neighbours after a pixel in raster order; the others see it as theirs
    for step, ok in ((1, u < cols - 1), (cols - 1, u > 0), (cols, True),
                     (cols + 1, u < cols - 1)):
        at = np.minimum(np.searchsorted(index, index + step), len(index) - 1)
        hit = ok & (index[at] == index + step)
        found.append((np.flatnonzero(hit), at[hit]))
    a, b = (np.concatenate(f) for f in zip(*found, strict=True))
    return a, b


def pieces(n: int, a: np.ndarray, b: np.ndarray) -> tuple[int, np.ndarray]:
    """Connected pieces of ``n`` pixels joined by the pairs (a, b): their number and each
    pixel's piece (n,), numbered from 0 in the order of each piece's first pixel."""
    graph = sparse.coo_array((np.ones(len(a), np.int8), (a, b)), shape=(n, n))
    return connected_components(graph, directed=False)
