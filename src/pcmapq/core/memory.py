"""The memory a run needs, estimated before its large steps allocate it, and the guard that
stops a run the machine cannot hold with one line instead of the kernel's kill.

A run's peak grows with four sizes (measured in docs/benchmarks.md, "Memory guard"): the cells
of the input images (read, classified, warped), the cells of the truth's grid (the rasters and
distance fields drawn on it), the cells of the working grid of the detectors (the walls' centre
lines, drawn at half of :data:`WORKING_CELL`, and the detectors' images), and the points of the
clouds. Each byte count below is the largest per-unit cost measured, so the estimate errs high.
"""

from __future__ import annotations

import os
from collections.abc import Callable

from pcmapq.core.errors import InputError

#: Resident memory of the imported libraries, bytes.
BASE = 450e6
#: Bytes per input image cell, per truth grid cell, per working cell and per cloud point. A
#: working cell's cost errs high (the 8000^2 campus pair peaks at under 40 B a working cell
#: beyond its images and grid): which of the detectors' biggest temporaries coincide varies
#: from run to run.
PER_IMAGE_CELL, PER_GRID_CELL, PER_WORKING_CELL, PER_POINT = 10, 17, 100, 100
#: The detectors' working cell, metres (:func:`pcmapq.features.walls.wall_image`).
WORKING_CELL = 0.05
#: The default limit: this share of the machine's memory.
DEFAULT_SHARE = 0.75


def machine_bytes() -> int:
    """The machine's physical memory, bytes."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def default_limit() -> int:
    """:data:`DEFAULT_SHARE` of the machine's memory, bytes."""
    return int(DEFAULT_SHARE * machine_bytes())


def needed_bytes(image_cells: int, grid_cells: int, extent_m2: float, points: int) -> int:
    """Estimated peak memory of a run, bytes: ``image_cells`` cells of input images,
    ``grid_cells`` cells of the truth's grid covering ``extent_m2`` square metres, ``points``
    cloud points."""
    working = extent_m2 / WORKING_CELL**2
    return int(BASE + PER_IMAGE_CELL * image_cells + PER_GRID_CELL * grid_cells
               + PER_WORKING_CELL * working + PER_POINT * points)


def guard(need: int, limit: int | None, what: str,
          advice: Callable[[], str] = lambda: "") -> None:
    """Raise InputError (exit 2, one line) when ``need`` bytes exceed ``limit`` (None: the
    default limit); ``what`` names the inputs, ``advice()`` says what looks wrong with them and
    how to fix it (empty: the general advice)."""
    default = ""
    if limit is None:
        limit = default_limit()
        default = f", {DEFAULT_SHARE:.0%} of this machine's {machine_bytes() / 1e9:.1f} GB"
    if need <= limit:
        return
    fix = advice() or ("a coarser --truth-resolution, a larger --voxel-3d or inputs cropped to "
                       "the region of interest (--map-crop, --truth-crop) need less")
    raise InputError(f"{what}: needs about {need / 1e9:,.1f} GB of memory, more than the limit "
                     f"of {limit / 1e9:.1f} GB (--max-memory{default}); {fix}")
