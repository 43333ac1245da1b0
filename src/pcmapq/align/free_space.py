"""A map's free space as evidence of its pose.

A laser sees nothing through a wall: a cell the map saw empty that a pose puts on a truth wall,
or inside a block the truth draws solid, contradicts that pose. A map wall on truth free space
is only furniture the truth lacks, so walls and free space weigh differently: a pose earns by
the map's walls that lie on truth walls and loses by the map's free cells that lie on truth
walls. Of the map's free cells that a pose puts where the truth knows what is there (its free
and occupied cells), the share on truth walls is the pose's *contradiction*: the disagreement of
Birk and Carpin's acceptance index for merging occupancy grids ("Merging occupancy grid maps
from multiple robots", Proc. IEEE 94(7), 2006), counted one way only. A pose that puts the
map's free space off the truth is not contradicted there, nor supported: the share of its free
cells on the truth's known cells is told beside (:meth:`FreeSpace.on_truth`).

Free cells within :data:`CLEAR_M` of a map wall are not evidence: where a wall's face lies
depends on how each side draws it and on the pose's last few centimetres.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import scipy.fft
from scipy.spatial import cKDTree

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import evenly, voxel_centroids

#: Free cells nearer than this to a map wall are left out, metres (at least 1.5 raster cells
#: where a raster is coarser).
CLEAR_M = 0.25
#: A pose's score is multiplied by exp(-PENALTY x its cost, :func:`cost`): a tenth of the
#: map's free space on truth walls divides it by 7.4.
PENALTY = 20.0
#: The cost of a free cell off the truth's known cells, against 1 for one on a truth wall,
#: beyond the first OFF_ALLOWED of the map's free cells: the truth says nothing there, and a map
#: of its place may see a little beyond it (through a door or window, or past a plan cut short
#: of its outer walls), but a map of another place placed to hang off the truth, most of its
#: free space off it, must not go free (docs/validation.md, the free-space section).
OFF_TRUTH, OFF_ALLOWED = 0.3, 0.2
#: Memory for the templates' spectra held at once, bytes.
FFT_BYTES = 64e6
#: Free points a final pose is checked with: a share is sure to about 1 % with this many.
CHECK_POINTS = 20_000
#: Fewest free points that are evidence on a raster coarser than the truth's (the global
#: search's, :meth:`FreeSpace.evidence`): there a wall is a cell thick, so a few of a small
#: map's free points land on the truth's walls even at its pose, and among a few dozen points
#: they cost that pose most of its score (the first 20 scans of CARMEN's ACES log: 28 points,
#: its pose dropped from the search). The poses the search keeps are still weighed by the free
#: space at the truth's own cell (:mod:`pcmapq.align.finalists`).
MIN_CLEAR = 100


@dataclass(frozen=True)
class FreeSpace:
    """The evidence of a map's free space for one map and one truth.

    free: (N, 2) metres, map frame: centres of the cells the map saw empty.
    solid: (rows, cols) bool on ``grid`` (truth frame): the truth's occupied cells, blocks
        drawn filled counted whole.
    known: (rows, cols) bool on ``grid``: the cells whose state the truth knows (an image's
        free and occupied cells; every cell of a cloud's grid).
    """

    free: np.ndarray
    solid: np.ndarray
    known: np.ndarray
    grid: MetricGrid

    def clear(self, walls_xy: np.ndarray, voxel: float, margin: float = CLEAR_M) -> np.ndarray:
        """The free points, map frame, thinned to ``voxel`` metres, farther than ``margin``
        metres from every map wall point ``walls_xy`` (N, 2, metres, map frame)."""
        free = voxel_centroids(self.free, voxel)
        if len(free) == 0 or len(walls_xy) == 0:
            return free
        dist, _ = cKDTree(walls_xy).query(free, distance_upper_bound=margin, workers=1)
        return free[~np.isfinite(dist)]

    def evidence(self, walls_xy: np.ndarray, cell: float) -> np.ndarray:
        """The free points (map frame, metres) that are evidence on a raster of ``cell``
        metres: thinned to half a cell, farther than CLEAR_M and 1.5 cells from the map's walls
        ``walls_xy`` (N, 2, map frame); none when fewer than MIN_CLEAR are left."""
        clear = self.clear(walls_xy, 0.5 * cell, max(CLEAR_M, 1.5 * cell))
        return clear if len(clear) >= MIN_CLEAR else clear[:0]

    def solid_xy(self) -> np.ndarray:
        """Centres of the truth's solid cells, (M, 2) metres, truth frame."""
        return self.grid.cell_centres(self.solid)

    def known_xy(self, cell: float) -> np.ndarray:
        """Centres of the truth's known cells, (M, 2) metres, truth frame, taken at a stride
        that leaves about one a ``cell`` metres (all of them at the grid's own cell)."""
        step = max(1, int(cell / self.grid.resolution))
        sub = np.zeros_like(self.known)
        sub[::step, ::step] = self.known[::step, ::step]
        return self.grid.cell_centres(sub)

    def contradiction(self, clear_xy: np.ndarray, tf: Similarity2D) -> float:
        """Share of the clear free points ``clear_xy`` (map frame) on the truth's known cells
        that ``tf`` puts on a solid truth cell, [0, 1]; 0 with none there."""
        moved = tf.apply(evenly(clear_xy, CHECK_POINTS))
        known = on_solid(self.known, self.grid, moved)
        if not known.any():
            return 0.0
        return float(on_solid(self.solid, self.grid, moved[known]).mean())

    def on_truth(self, clear_xy: np.ndarray, tf: Similarity2D) -> float:
        """Share of the clear free points ``clear_xy`` (map frame) that ``tf`` puts on the
        truth's known cells, [0, 1]; 0 without free points."""
        if len(clear_xy) == 0:
            return 0.0
        return float(on_solid(self.known, self.grid,
                              tf.apply(evenly(clear_xy, CHECK_POINTS))).mean())


def cost(contradiction: float | None, on_truth: float | None) -> float:
    """What a pose's free space costs it, [0, 1]: the share of the map's free cells on truth
    walls, plus OFF_TRUTH times the share off the truth's known cells beyond OFF_ALLOWED; 0
    without free space."""
    if contradiction is None or on_truth is None:
        return 0.0
    return contradiction * on_truth + _off(1.0 - on_truth)


def _off(share: np.ndarray | float) -> np.ndarray | float:
    """The cost of a share of free cells off the truth."""
    return OFF_TRUTH * np.maximum(share - OFF_ALLOWED, 0.0)


def contradictions(solid: np.ndarray, known: np.ndarray,
                   templates: np.ndarray) -> Iterator[np.ndarray]:
    """For each binary template (yaws, size, size) of a map's free cells, the :func:`cost` of
    every place of it on the truth's rasters ``solid`` and ``known`` (rows, cols; 1 on a
    solid or known cell): a (rows - size + 1, cols - size + 1) array laid out as
    cv2.matchTemplate's responses. The rasters' spectra are taken once and the templates' a
    batch at a time (scipy.fft in single precision: the counts, whole numbers below 2^20, come
    back exact once rounded)."""
    rows, cols = solid.shape
    size = templates.shape[-1]
    # no wrap: a valid place reads up to rows - 1, cols - 1
    shape = (scipy.fft.next_fast_len(rows, True), scipy.fft.next_fast_len(cols, True))
    spectra = scipy.fft.rfft2(np.stack([solid, known]).astype(np.float32), s=shape)
    batch = max(1, int(FFT_BYTES // (8 * shape[0] * (shape[1] // 2 + 1))))
    for start in range(0, len(templates), batch):
        chunk = templates[start:start + batch]
        total = np.maximum(chunk.sum(axis=(1, 2)), 1.0)[:, None, None]
        counts = scipy.fft.irfft2(spectra[:, None] * np.conj(scipy.fft.rfft2(chunk, s=shape)),
                                  s=shape)
        walls, known_cells = np.rint(counts[:, :, :rows - size + 1, :cols - size + 1])
        yield from (walls / total + _off(1.0 - known_cells / total)).astype(np.float32)


def on_solid(solid: np.ndarray, grid: MetricGrid, xy: np.ndarray) -> np.ndarray:
    """Whether each point (N, 2, metres, the grid's frame) lies in a ``solid`` cell of
    ``grid``; points off the grid lie on nothing."""
    uv = np.floor(grid.xy_to_pixels(xy) + 0.5).astype(np.int64)
    rows, cols = solid.shape
    inside = (uv[:, 0] >= 0) & (uv[:, 0] < cols) & (uv[:, 1] >= 0) & (uv[:, 1] < rows)
    hit = np.zeros(len(xy), bool)
    hit[inside] = solid[uv[inside, 1], uv[inside, 0]]
    return hit
