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
#: working cell's cost errs high: which of the detectors' biggest temporaries coincide varies
#: from run to run, and the estimate assumes the worst.
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
    return int(BASE + sum(parts(image_cells, grid_cells, extent_m2, points).values()))


def parts(image_cells: int, grid_cells: int, extent_m2: float, points: int) -> dict[str, float]:
    """The parts of :func:`needed_bytes` beyond :data:`BASE`, bytes: ``images``, ``grid`` (the
    truth's), ``working`` (the detectors' cells of :data:`WORKING_CELL` over ``extent_m2``,
    whatever the grid's cell size) and ``points``."""
    return {"images": float(PER_IMAGE_CELL * image_cells),
            "grid": float(PER_GRID_CELL * grid_cells),
            "working": PER_WORKING_CELL * extent_m2 / WORKING_CELL**2,
            "points": float(PER_POINT * points)}


def more_memory(need: int) -> str:
    """The general advice for ``need`` bytes over the limit: a higher --max-memory when this
    machine has that much, else a smaller input."""
    machine = machine_bytes()
    if need < machine:
        return (f"a --max-memory of {need / 1e9:.1f} GB or more runs it, if this machine's "
                f"{machine / 1e9:.1f} GB can spare that; else a smaller input")
    return f"more than this machine's {machine / 1e9:.1f} GB: a smaller input"


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
    fix = advice() or more_memory(need)
    raise InputError(f"{what}: needs about {need / 1e9:,.1f} GB of memory, more than the limit "
                     f"of {limit / 1e9:.1f} GB (--max-memory{default}); {fix}")


def check_points(path: object, count: int, memory_limit: int | None = None) -> None:
    """InputError (one line) when ``count`` points, declared by the file ``path``, need more
    memory than ``memory_limit`` bytes (None: the default limit)."""
    guard(needed_bytes(0, 0, 0.0, int(count)), memory_limit,
          f"{path} ({count:,} points declared)")
