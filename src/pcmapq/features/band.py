"""The walls' centre lines drawn back as an anti-aliased band (step 5 of
:mod:`pcmapq.features.walls`), visiting the line's cells and their neighbourhood only.

A cell's shade is ``0.5 + half width - d`` clipped to [0, 1], d its Euclidean distance (cells)
to the nearest line cell: only cells closer than ``half width + 0.5`` get any. The shade falls
as d grows, so a cell's shade is the largest over the line cells within that reach, each giving
the shade of its own offset, from the offset's distance (the float32 square root of a whole
number of cells squared). The distance transform (:func:`pcmapq.core.morphology.distance_to`,
OpenCV's) gives the same distances up to 6 cells, so for a half width of up to 5.5 cells (the
walls' band is 3) the band is the same, cell for cell, as shading a distance transform of the
whole raster, at a cost that follows the line's length. Farther out OpenCV rounds some
distances a float32 step lower, depending on the cell's place in its vector loop.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["draw_band"]


def draw_band(line: np.ndarray, half_width: float, out: np.ndarray) -> np.ndarray:
    """``out`` (float32, the shape of ``line``) raised in place to the band's shade wherever
    that is higher: the band ``2 * half_width`` cells wide along the set cells of ``line``
    (bool), shaded as the module docstring says. Returns ``out``."""
    reach = int(np.ceil(half_width + 0.5))
    dy, dx = np.mgrid[-reach:reach + 1, -reach:reach + 1]
    shade = np.sqrt((dy * dy + dx * dx).astype(np.float32))
    # the arithmetic a whole distance transform's shading does, in float32
    np.subtract(half_width, shade, out=shade)
    np.add(0.5, shade, out=shade)
    np.clip(shade, 0.0, 1.0, out=shade)
    some = shade > 0
    rows, cols = np.nonzero(line)
    _raise(out, rows.astype(np.int64), cols.astype(np.int64), dy[some].astype(np.int64),
           dx[some].astype(np.int64), shade[some])
    return out


# compiled (or read from the cache) at import, in the importing thread: compiled lazily, on a
# drawing thread of an evaluation that outlived its command, the next command run in the
# process found its output streams closed (tests/cli without a terminal, from a cold cache)
@numba.njit(numba.void(numba.float32[:, :], numba.int64[::1], numba.int64[::1], numba.int64[::1],
                       numba.int64[::1], numba.float32[::1]), cache=True, nogil=True)
def _raise(out: np.ndarray, rows: np.ndarray, cols: np.ndarray, dy: np.ndarray, dx: np.ndarray,
           shade: np.ndarray) -> None:
    """out[r + dy, c + dx] = max(itself, shade) for every line cell (r, c) and offset."""
    height, width = out.shape
    for k in range(len(rows)):
        for j in range(len(dy)):
            r, c = rows[k] + dy[j], cols[k] + dx[j]
            if 0 <= r < height and 0 <= c < width and out[r, c] < shade[j]:
                out[r, c] = shade[j]
