"""Block pooling of a raster: the smaller raster a picture draws, one cell per ``factor`` x
``factor`` block of cells.

Block ``(i, j)`` holds cells ``[i f, (i + 1) f) x [j f, (j + 1) f)``; the last row and column of
blocks are partial when the shape is not a multiple of ``f``, so the pooled raster has
``ceil(rows / f) x ceil(cols / f)`` cells and covers the source's cells and, past its bottom and
right edges, less than one block more. Rows are reduced first, ``f`` at a time, on a reshaped
view of the source (no padded copy of it: the partial last block is reduced on its own), then
columns on that ``f`` times smaller result; no Python loop over cells, and cheaper than
``ufunc.reduceat`` over the same blocks.
"""

from __future__ import annotations

import numpy as np


def _pool_rows(values: np.ndarray, factor: int, ufunc: np.ufunc) -> np.ndarray:
    """``ufunc`` reduced over each ``factor`` rows of the 2D ``values`` (the last ones partial)."""
    whole = values.shape[0] // factor * factor
    parts = [ufunc.reduce(values[:whole].reshape(-1, factor, values.shape[1]), axis=1)]
    if whole < values.shape[0]:
        parts.append(ufunc.reduce(values[whole:], axis=0, keepdims=True))
    return np.concatenate(parts)


def _pool(values: np.ndarray, factor: int, ufunc: np.ufunc) -> np.ndarray:
    """``ufunc`` reduced over each ``factor`` x ``factor`` block of the 2D ``values``."""
    if factor < 1:
        raise ValueError(f"pooling factor must be at least 1, not {factor}")
    if factor == 1:
        return values
    rows = _pool_rows(values, factor, ufunc)
    return np.ascontiguousarray(_pool_rows(rows.T, factor, ufunc).T)


def max_pool(values: np.ndarray, factor: int) -> np.ndarray:
    """The largest value of each ``factor`` x ``factor`` block: (rows, cols) bool, uint8 or
    float32 -> (ceil(rows / factor), ceil(cols / factor)), same dtype. On a wall mask a block is
    a wall if any of its cells is, so walls one cell thin survive. ``values`` itself when
    ``factor`` is 1."""
    return _pool(values, factor, np.maximum)


def min_pool(values: np.ndarray, factor: int) -> np.ndarray:
    """The smallest value of each ``factor`` x ``factor`` block, ignoring NaN (a block of NaN
    stays NaN): (rows, cols) float32 or uint8 -> (ceil(rows / factor), ceil(cols / factor)),
    same dtype. ``values`` itself when ``factor`` is 1."""
    return _pool(values, factor, np.fmin)


def mean_pool(mask: np.ndarray, factor: int) -> np.ndarray:
    """The share of true cells in each ``factor`` x ``factor`` block of a bool mask (partial
    blocks over their own cells): (rows, cols) bool -> (ceil(rows / factor),
    ceil(cols / factor)) float64 in [0, 1]."""
    counts = _pool(mask, factor, np.add).astype(np.float64)
    rows, cols = (np.minimum(factor, n - np.arange(0, n, factor)) for n in mask.shape)
    return counts / np.outer(rows, cols)
