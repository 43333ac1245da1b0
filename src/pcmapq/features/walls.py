"""The drawing-independent view of the walls that every detector sees.

A wall can be drawn one cell thin (a Gazebo render, a CAD export), two or three cells wide (a
SLAM map), 0.3 m thick (a building plan), or as its two faces with or without a fill (a plan
drawn as outlines, a wall seen from both sides by a laser). The geometry is the same; the cells
are not, and detectors tuned on one drawing see another one differently (a one-cell wall at
0.025 m is a quarter-strength line on a 0.05 m working grid; a 0.3 m wall has corners where a
thin one has none). So the detectors never see the cells as drawn. They see the walls'
**centre lines** redrawn as a band of one fixed width:

1. the occupied cells are resampled onto a fine grid (half the working cell); a fine cell is a
   wall when any part of it is (so a one-cell wall of a much finer image survives);
2. a closing with a disc of ``closing`` metres joins the two faces of a wall drawn as outlines
   (faces up to about twice that apart) and bridges one-cell breaks;
3. the result is thinned to its skeleton (Zhang and Suen's thinning as scikit-image's
   ``skeletonize`` does it, :mod:`pcmapq.features.thinning`), the medial axis: one
   line per wall, whatever its thickness up to :data:`THICKEST` metres. A thicker area is no
   wall but a filled region: its cells deeper than half that (the centres of a square of
   that half-side all wall; a diagonal wall that thick holds none) are left out first, so it is
   thinned as a band ``THICKEST / 2`` wide along its outline;
4. spurs are pruned: a branch that ends free and meets the rest of the skeleton at a junction
   is dropped when it is shorter than ``spur`` metres. These are the branches the medial axis
   grows into the outer corner of a thick wall's bend and into the two corners of a thick
   wall's square end; the centre line then ends where the wall's geometry does;
5. the centre lines are drawn back as an anti-aliased band ``width`` metres wide (shaded by
   the Euclidean distance to them, :mod:`pcmapq.features.band`) and area-averaged onto the
   working grid.

What the detectors see then depends on where the walls are, not on how many cells paint them.

Only the window of the raster that holds walls is drawn (their bounding box and
:data:`MARGIN` metres of empty cells around it; the rest is 0): beyond the walls every step sees
empty cells only, and none reaches farther into them than the margin (the closing's 0.1 m, the
band's half width), so the window gives the image the whole raster would. A window larger than
:data:`TILE` working cells a side is drawn tile by tile (each with a halo of :data:`HALO` metres
that is drawn and dropped), on as many threads as there are cores (at most 4): every step looks
no farther than the halo, so the tiles join into the same image, in a bounded memory. The
process draws no more tiles at once than that, whichever images they belong to (the truth's,
the map's and the map's own figures may be drawn at the same time), so that the largest
temporaries do not pile up with the number of images.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from threading import BoundedSemaphore

import cv2
import numpy as np

from pcmapq.core.bounds import nonzero_window
from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import disc, distance_to
from pcmapq.features.band import draw_band
from pcmapq.features.pixels import flat_index, neighbour_pairs
from pcmapq.features.pixels import pieces as connected
from pcmapq.features.resample import covered, resample
from pcmapq.features.thinning import skeletonize

#: Working cells a side of a tile of a large raster, and the halo drawn around each, metres:
#: more than any step looks (a small object's 1 m, a spur's 0.25 m, the closing's 0.1 m).
TILE, HALO = 2048, 4.0
#: Empty margin kept around the walls' bounding box, metres: more than any step reaches into
#: empty cells (the closing's disc, the band's half width and a cell).
MARGIN = 0.5
#: The thickest wall, metres: thicker occupied areas are filled regions (module docstring, 3).
THICKEST = 2.0
#: Threads drawing tiles, at most.
THREADS = 4
#: Tiles drawn at once in the process, over all images.
_DRAWING = BoundedSemaphore(min(THREADS, os.cpu_count() or 1))
#: The closing's radius, metres (module docstring, 2): readings of a wall up to about twice this
#: apart join into one line.
CLOSING = 0.1


def prune(skeleton: np.ndarray, shortest_px: float) -> np.ndarray:
    """The skeleton (bool) without its spurs: branches that end free and meet the rest at a
    junction, shorter than ``shortest_px`` pixels. Branches are the connected runs left when
    the junction pixels (three or more neighbours) are taken out. Only the skeleton's pixels
    are visited (:mod:`pcmapq.features.pixels`)."""
    v, u, index = flat_index(skeleton)
    a, b = neighbour_pairs(index, skeleton.shape[1])
    count = np.bincount(a, minlength=len(index)) + np.bincount(b, minlength=len(index))
    junction = count >= 3
    branch = ~junction
    n, label = connected(len(index), a[branch[a] & branch[b]], b[branch[a] & branch[b]])
    length = np.bincount(label[branch], minlength=n)
    free_end = np.bincount(label[count <= 1], minlength=n) > 0
    touch = junction[a] != junction[b]  # a branch pixel next to a junction
    at_junction = np.zeros(n, dtype=bool)
    at_junction[label[np.where(junction[a[touch]], b[touch], a[touch])]] = True
    spur = free_end & at_junction & (length < shortest_px)
    drop = branch & spur[label]
    pruned = skeleton.copy()
    pruned[v[drop], u[drop]] = False
    return pruned


def centreline(occupied: np.ndarray, grid: MetricGrid, resolution: float, closing: float,
               spur: float, small: float,
               width: float) -> tuple[np.ndarray, np.ndarray, MetricGrid]:
    """The walls' centre lines and the cores of the small objects, on a grid of ``resolution``
    metres (same origin and yaw as ``grid``): steps 1-4 of the module docstring.

    occupied: (rows, cols) bool on ``grid``, walls true. closing: radius of the closing disc,
    metres. spur: shortest free branch kept, metres. small: a piece at most this wide and high
    (metres) is an object, not a wall; width: width of its core, metres (see :func:`cores`).

    Returns the one-pixel bool centre lines, the bool object cores and their grid.
    """
    wall, fine = covered(occupied, grid, resolution)
    kernel = disc(closing / resolution)
    pad = kernel.shape[0]
    wall = cv2.morphologyEx(np.pad(wall, pad), cv2.MORPH_CLOSE, kernel)[pad:-pad, pad:-pad]
    n, label, stats, _ = cv2.connectedComponentsWithStats(wall, connectivity=8)
    size = np.maximum(stats[:, cv2.CC_STAT_WIDTH], stats[:, cv2.CC_STAT_HEIGHT]) * resolution
    is_small = size <= small
    is_small[0] = False
    half = int(0.5 * THICKEST / resolution)  # deep: a square of this half-side all wall
    deep = cv2.erode(wall, cv2.getStructuringElement(cv2.MORPH_RECT, (2 * half + 1,) * 2),
                     borderType=cv2.BORDER_CONSTANT, borderValue=0)
    walls = wall > deep  # wall cells that are not deep
    if not is_small.any():  # no object: nothing to fill or take out (most tiles of a campus)
        return prune(skeletonize(walls), spur / resolution), np.zeros_like(walls), fine
    objects = fill_holes(is_small[label])
    line = prune(skeletonize(walls & ~objects), spur / resolution)
    return line, cores(objects, width / resolution), fine


def fill_holes(mask: np.ndarray) -> np.ndarray:
    """``mask`` (bool) with its holes filled: the 4-connected pieces of its complement that do
    not reach the border (one flood fill from around the border). The holes of small objects
    lie within them, so they are small too."""
    outside = np.pad(~mask, 1, constant_values=True).view(np.uint8)
    cv2.floodFill(outside, None, (0, 0), 2)  # 4-connected
    return mask | (outside[1:-1, 1:-1] == 1)


def cores(objects: np.ndarray, width_px: float) -> np.ndarray:
    """The core of each object (bool): its cells within ``width_px / 2`` pixels of its deepest
    depth (Euclidean distance to its outside). A solid block and a ring of thin walls around
    the same spot, filled, have the same core, about ``width_px`` across.

    Computed on the rows and columns that hold object cells or touch one: the others hold
    outside cells only, and an all-outside row or column is kept between any two objects, so
    dropping the rest changes no cell's depth and joins no two objects."""
    if not objects.any():
        return objects
    rows, cols = _lines_near(objects)
    crop = objects[np.ix_(rows, cols)]
    _, label = cv2.connectedComponents(crop.astype(np.uint8), connectivity=8)
    depth = distance_to(np.pad(~crop, 1, constant_values=True))[1:-1, 1:-1]
    v, u = np.nonzero(crop)  # the object cells: all that is compared, not the whole crop
    own, deep = label[v, u], depth[v, u]
    deepest = np.zeros(label.max() + 1, dtype=np.float32)
    np.maximum.at(deepest, own, deep)
    keep = deep >= deepest[own] - 0.5 * width_px
    core = np.zeros_like(objects)
    core[rows[v[keep]], cols[u[keep]]] = True
    return core


def _lines_near(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows and the columns of ``mask`` (bool) that hold a true cell or lie next to one
    (:func:`_touched`): the crop on which :func:`cores` works."""
    return _touched(mask.any(axis=1)), _touched(mask.any(axis=0))


def _touched(held: np.ndarray) -> np.ndarray:
    """Indices of the lines (rows or columns) that hold cells of interest (``held``, bool per
    line) or lie next to one."""
    near = held.copy()
    near[1:] |= held[:-1]
    near[:-1] |= held[1:]
    return np.flatnonzero(near)


@dataclass(frozen=True)
class WallImage:
    """The walls as the detectors see them.

    image: (rows, cols) float32 in [0, 1], the wall band's share of each working cell.
    grid: the working grid (same origin and yaw as the input raster's grid).
    """

    image: np.ndarray
    grid: MetricGrid


def wall_image(occupied: np.ndarray, grid: MetricGrid, resolution: float = 0.05,
               closing: float = CLOSING, width: float = 0.15, spur: float = 0.25,
               small: float = 1.0, tile: int = TILE) -> WallImage:
    """The walls as the detectors see them: their centre lines drawn ``width`` metres wide.

    Parameters
    ----------
    occupied : (rows, cols) bool raster on ``grid``, walls true.
    grid : the raster's grid.
    resolution : working cell size, metres; centre lines are found on cells half as large.
    closing : closing radius, metres: the two faces of a wall drawn up to about twice this apart
        become one wall.
    width : width of the band drawn along each centre line, metres.
    spur : free branches of the centre lines shorter than this are dropped, metres.
    small : an object at most this wide and high, metres (a pillar, a box), is drawn as its
        core instead, ``width`` across: a ring of thin walls and a solid block of thick ones
        are the same object.
    tile : working cells a side of the tiles a window of walls larger than that is drawn in,
        when the working cell is a whole number of raster cells (otherwise the raster is drawn
        whole, without a window).

    Returns
    -------
    The :class:`WallImage` on a grid of ``resolution`` metres.
    """
    k = int(round(resolution / grid.resolution))
    if k < 1 or abs(resolution - k * grid.resolution) > 1e-9 * resolution:
        return WallImage(_band(occupied, grid, resolution, closing, width, spur, small),
                         grid.resampled(resolution))
    return _tiled(occupied, grid, resolution, k, tile,
                  lambda crop, sub: _band(crop, sub, resolution, closing, width, spur, small),
                  _window(occupied, k, k * int(np.ceil(MARGIN / resolution))))


def _window(occupied: np.ndarray, k: int, margin: int) -> tuple[int, int, int, int]:
    """Rows (counted from the bottom) and columns ``lo, hi, left, right`` of the raster's
    cells that hold walls, widened by ``margin`` cells and to whole working cells of ``k``
    raster cells from the lower-left corner, within the raster; empty when none does."""
    window = nonzero_window(occupied[::-1], margin)
    if window is None:
        return 0, 0, 0, 0
    lo, hi, left, right = window
    rows, cols = occupied.shape
    return lo // k * k, min(rows, -(-hi // k) * k), left // k * k, min(cols, -(-right // k) * k)


def _tiled(occupied: np.ndarray, grid: MetricGrid, resolution: float, k: int, tile: int,
           band, window: tuple[int, int, int, int]) -> WallImage:
    """:func:`wall_image` of the cells within ``window`` (see :func:`_window`; the others
    are empty), tile by tile: ``band(crop, crop_grid)`` draws one haloed crop, cut to the
    window; the working cell is ``k`` raster cells. Rows are counted from the bottom here,
    where the working grid is anchored (the grid's origin is the image's lower-left corner)."""
    rows = occupied.shape[0]
    work = grid.resampled(resolution)
    halo = k * int(np.ceil(HALO / resolution))
    step = tile * k
    below = occupied[::-1]  # row 0 at the bottom
    out = np.zeros(work.shape, np.float32)[::-1]
    from_row, to_row, from_col, to_col = window

    def draw(p: int, c: int) -> None:
        lo, hi = max(from_row, p - halo), min(to_row, p + step + halo)
        left, right = max(from_col, c - halo), min(to_col, c + step + halo)
        corner = grid.pixels_to_xy(np.array([[left - 0.5, rows - lo - 0.5]]))[0]
        sub = MetricGrid(grid.resolution, (float(corner[0]), float(corner[1]), grid.origin[2]),
                         (hi - lo, right - left))
        with _DRAWING:
            got = band(np.ascontiguousarray(below[lo:hi, left:right][::-1]), sub)[::-1]
        top, end = -(-min(to_row, p + step) // k), -(-min(to_col, c + step) // k)
        out[p // k:top, c // k:end] = got[(p - lo) // k:(p - lo) // k + top - p // k,
                                          (c - left) // k:(c - left) // k + end - c // k]

    starts = [(p, c) for p in range(from_row, to_row, step)
              for c in range(from_col, to_col, step)]
    with ThreadPoolExecutor(min(THREADS, os.cpu_count() or 1)) as pool:
        list(pool.map(lambda pc: draw(*pc), starts))
    return WallImage(np.ascontiguousarray(out[::-1]), work)


def _band(occupied: np.ndarray, grid: MetricGrid, resolution: float, closing: float,
          width: float, spur: float, small: float) -> np.ndarray:
    """:func:`wall_image`'s image for the whole raster: (rows, cols) float32 on
    ``grid.resampled(resolution)``."""
    fine_res = 0.5 * resolution
    line, core, fine = centreline(occupied, grid, fine_res, closing, spur, small, width)
    band = draw_band(line, 0.5 * width / fine_res, core.astype(np.float32))
    return resample(band, fine, resolution)[0]
