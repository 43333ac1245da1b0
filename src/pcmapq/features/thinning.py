"""Zhang and Suen's thinning of a binary image, as scikit-image's ``skeletonize`` gives it, with
work in proportion to the set cells instead of the image.

scikit-image scans every cell of the image on each of the algorithm's sub-passes, and a wall
band a few cells wide takes several; on a sparse raster (walls are a few percent of a campus)
almost all of that is empty cells. The algorithm is parallel: a sub-pass decides every cell
from its 8 neighbours as they were when the sub-pass began, then removes what it decided. So a
cell kept by a sub-pass of one kind is kept again by the next of that kind unless a neighbour
was removed in between, and only those cells need to be looked at again: each kind of sub-pass
visits the set cells it has not seen since their neighbourhood changed, and the cells removed
are the same, sub-pass by sub-pass (Zhang and Suen, "A fast parallel algorithm for thinning
digital patterns", CACM 27(3), 1984; scikit-image's table of neighbourhoods).
"""

from __future__ import annotations

import cv2
import numba
import numpy as np

__all__ = ["skeletonize"]

#: scikit-image's table: for each neighbourhood (bit k set when neighbour k is, clockwise from
#: the upper-left: 1 upper-left, 2 up, 4 upper-right, 8 right, 16 lower-right, 32 down,
#: 64 lower-left, 128 left), 1: removed by the first sub-pass, 2: by the second, 3: by both.
LUT = np.array([
    0, 0, 0, 1, 0, 0, 1, 3, 0, 0, 3, 1, 1, 0, 1, 3, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2, 0, 3, 0, 3, 3,
    0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 3, 0, 2, 2,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    2, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 3, 0, 2, 0,
    0, 0, 3, 1, 0, 0, 1, 3, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1,
    3, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    2, 3, 1, 3, 0, 0, 1, 3, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    2, 3, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 3, 3, 0, 1, 0, 0, 0, 0, 2, 2, 0, 0, 2, 0, 0, 0,
], dtype=np.uint8)


def skeletonize(mask: np.ndarray) -> np.ndarray:
    """The skeleton (bool, the shape of ``mask``) of the set cells of ``mask`` (rows, cols):
    ``skimage.morphology.skeletonize(mask)`` cell for cell."""
    image = np.pad(np.asarray(mask, dtype=bool), 1).view(np.uint8)  # a border of empty cells
    # a cell whose 8 neighbours are all set stays (the table's last entry is 0): only the
    # cells next to an empty one need a first look
    inner = cv2.erode(image, np.ones((3, 3), np.uint8))
    _thin(image, np.flatnonzero(image > inner), LUT)
    return np.ascontiguousarray(image[1:-1, 1:-1]).view(bool)


# compiled (or read from the cache) at import, in the importing thread: compiled lazily, on a
# drawing thread of an evaluation that outlived its command, the next command run in the
# process found its output streams closed (tests/cli without a terminal, from a cold cache)
@numba.njit(numba.void(numba.uint8[:, ::1], numba.int64[::1], numba.uint8[::1]), cache=True,
            nogil=True)
def _thin(image: np.ndarray, cells: np.ndarray, lut: np.ndarray) -> None:
    """Thin ``image`` (uint8 0/1, its border cells 0) in place: sub-passes of the first and the
    second kind in turn, until a first and a second remove nothing (module docstring). cells:
    the flat indices of the set cells that may be removed first."""
    cols = image.shape[1]
    flat = image.ravel()
    count = int(np.count_nonzero(flat))
    # the cells each kind of sub-pass is to look at, each listed once at a time
    todo = np.empty((2, count), np.int64)
    listed = np.zeros(flat.size, np.uint8)  # bit 1 << kind: on that kind's list
    for k in range(len(cells)):
        todo[0, k] = todo[1, k] = cells[k]
        listed[cells[k]] = 3
    length = np.array([len(cells), len(cells)])
    removed = np.empty(count, np.int64)
    step = np.array([-cols - 1, -cols, -cols + 1, 1, cols + 1, cols, cols - 1, -1])
    while True:
        changed = False
        for kind in range(2):
            n_removed = 0
            for k in range(length[kind]):
                i = todo[kind, k]
                listed[i] &= ~np.uint8(1 << kind)
                if flat[i] == 0:
                    continue
                code = 0
                for b in range(8):
                    code |= flat[i + step[b]] << b
                v = lut[code]
                if v == 3 or v == kind + 1:
                    removed[n_removed] = i
                    n_removed += 1
            length[kind] = 0
            for k in range(n_removed):
                flat[removed[k]] = 0
            for k in range(n_removed):
                for b in range(8):
                    j = removed[k] + step[b]
                    if flat[j] and listed[j] != 3:
                        for other in range(2):
                            if not listed[j] & (1 << other):
                                todo[other, length[other]] = j
                                length[other] += 1
                        listed[j] = 3
            changed |= n_removed > 0
        if not changed:
            return
