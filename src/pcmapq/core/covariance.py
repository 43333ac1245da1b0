"""Symmetric 3 x 3 matrices (covariances, scatter sums) from their six distinct entries, as a
per-point or per-voxel sum accumulates them: one 1-D sum per pair of axes (PAIRS)."""

from __future__ import annotations

import numpy as np

__all__ = ["PAIRS", "symmetric"]

#: The pairs of axes of a symmetric 3 x 3 matrix's six distinct entries.
PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def symmetric(entries: np.ndarray) -> np.ndarray:
    """(V, 3, 3) matrices from their entries (6, V) in PAIRS order."""
    entries = np.asarray(entries)
    out = np.empty((entries.shape[1], 3, 3))
    for k, (a, b) in enumerate(PAIRS):
        out[:, a, b] = out[:, b, a] = entries[k]
    return out
