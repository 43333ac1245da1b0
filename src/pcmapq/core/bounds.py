"""Bounding boxes: of many points, column by column, and of the nonzero cells of an image;
the radius of points about their centroid; the labels that reach a raster's edge.

NumPy reduces an (N, d) array over axis 0 with a strided inner loop, which the columns one at
a time avoid (the box is the same, for a fraction of the time).
"""

from __future__ import annotations

import numpy as np

#: A box ``(x0, y0, x1, y1)``, metres, in some input's own frame (a crop: :mod:`pcmapq.io.extent`).
Box = tuple[float, float, float, float]


def bounds(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least and the greatest value of each column of ``points`` (N, d), N >= 1: two (d,)
    arrays of its dtype, equal to ``points.min(axis=0)`` and ``points.max(axis=0)``."""
    points = np.asarray(points)
    columns = [points[:, i] for i in range(points.shape[1])]
    return (np.array([c.min() for c in columns], dtype=points.dtype),
            np.array([c.max() for c in columns], dtype=points.dtype))


def nonzero_window(image: np.ndarray, margin: int = 0) -> tuple[int, int, int, int] | None:
    """The box of the nonzero cells of ``image`` (rows, cols) grown by ``margin`` cells and cut
    to the image: ``lo, hi, left, right``, rows ``lo:hi`` and columns ``left:right`` (in the
    array's own order); None when every cell is zero."""
    rows = np.flatnonzero(image.any(axis=1))
    if not len(rows):
        return None
    cols = np.flatnonzero(image.any(axis=0))
    return (max(0, int(rows[0]) - margin), min(image.shape[0], int(rows[-1]) + 1 + margin),
            max(0, int(cols[0]) - margin), min(image.shape[1], int(cols[-1]) + 1 + margin))


def radius(xy: np.ndarray) -> float:
    """Largest distance of points (N, 2) from their centroid, in their unit."""
    return float(np.sqrt(((xy - xy.mean(axis=0)) ** 2).sum(axis=1).max()))


def on_edge(labels: np.ndarray, count: int) -> np.ndarray:
    """(count,) bool: which of the labels 0 .. count - 1 of the raster ``labels`` (int, rows x
    cols) have a cell in its first or last row or column."""
    edge = np.zeros(count, dtype=bool)
    for line in (labels[0], labels[-1], labels[:, 0], labels[:, -1]):
        edge[line] = True
    return edge
