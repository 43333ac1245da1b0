"""A map's run cut into stretches: consecutive scans, the same number in each, for a map whose
points carry the scan they came from (:mod:`pcmapq.mapping.scan_map`; a point's scan is the
mean index of the scans its voxel holds). :mod:`pcmapq.align.regions3d` registers each stretch
on its own."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

__all__ = ["MAX_STRETCHES", "MOST_STRETCHES", "STRETCH_SCANS", "run_stretches",
           "stretch_scans", "stretches"]

#: A stretch of the run holds at least this many scans; the run is cut into at most
#: MAX_STRETCHES stretches, each of the same number of scans.
STRETCH_SCANS = 4
MAX_STRETCHES = 32
#: A stretch asked for (``--stretch-3d``) may cut the run into at most this many stretches.
MOST_STRETCHES = 10_000


def stretch_scans(span: float) -> int:
    """The scans a stretch of a run holds whose points' scans span ``span`` (last less first):
    at least STRETCH_SCANS, and as many as cut the run into at most MAX_STRETCHES."""
    scans = int(np.ceil(span)) + 1
    return max(STRETCH_SCANS, -(-scans // MAX_STRETCHES))


def run_stretches(scan: np.ndarray, stretch: int | None) -> tuple[int, int, int]:
    """The run's first and last scan (``scan`` (N,) each point's: a voxel's is a mean, so
    rounded out) and the scans a stretch holds (``stretch``; None: :func:`stretch_scans`).
    ValueError, saying why in one line, when that cuts the run into more than
    MOST_STRETCHES."""
    scan = np.asarray(scan)
    first, last = int(np.floor(scan.min())), int(np.ceil(scan.max()))
    stretch = stretch or stretch_scans(last - first)
    count = last // stretch - first // stretch + 1
    if count > MOST_STRETCHES:
        raise ValueError(f"--stretch-3d {stretch}: the map's scans run from {first} to "
                         f"{last}: {count} stretches of {stretch}, more than {MOST_STRETCHES}; "
                         "give a larger stretch, or 0 for tiles")
    return first, last, stretch


def stretches(scan: np.ndarray, stretch: int | None
              ) -> tuple[int, Iterator[tuple[np.ndarray, tuple[int, int]]]]:
    """The scans a stretch holds (:func:`run_stretches`, whose ValueError it raises), and each
    stretch that holds points, in the run's order: the indices (increasing) of its points
    among ``scan`` (N,) and its first and last scan. Each point's stretch is a small integer,
    sorted once (stably, so that a stretch's points keep their order): each stretch's points
    are one slice of that order."""
    scan = np.asarray(scan)
    first, last, stretch = run_stretches(scan, stretch)
    low = first // stretch
    of = (np.floor(scan / stretch) - low).astype(np.int16)
    order = np.argsort(of, kind="stable")
    counts = np.bincount(of)
    bounds_at = np.concatenate([[0], np.cumsum(counts)])

    def each() -> Iterator[tuple[np.ndarray, tuple[int, int]]]:
        for k in np.flatnonzero(counts):
            start = (int(k) + low) * stretch
            yield (order[bounds_at[k]:bounds_at[k + 1]],
                   (max(start, first), min(start + stretch - 1, last)))

    return stretch, each()
