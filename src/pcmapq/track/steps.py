"""When a run is scored: every N scans or every D metres travelled, and always at its end."""

from __future__ import annotations

import numpy as np


def travelled(poses: np.ndarray) -> np.ndarray:
    """(K,) distance travelled up to each pose along the path of its positions, metres (0 at
    the first); ``poses`` (K, 4, 4)."""
    xyz = np.asarray(poses, dtype=np.float64)[:, :3, 3]
    steps = np.linalg.norm(np.diff(xyz, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def step_ends(count: int, every: int | None = None, every_m: float | None = None,
              distance: np.ndarray | None = None) -> np.ndarray:
    """(S,) int, increasing: how many scans the map holds at each step, the last ``count``.

    every: a step every this many scans; every_m: a step at the first scan that reaches each
    multiple of this many metres travelled (``distance``, (count,) metres, from
    :func:`travelled`). One of the two; a step is never empty and never repeated."""
    if (every is None) == (every_m is None):
        raise ValueError("give one of every (scans) and every_m (metres)")
    if every is not None:
        ends = np.arange(every, count + 1, every)
    else:
        if distance is None or len(distance) != count:
            raise ValueError("every_m needs the distance travelled at each of the scans")
        marks = np.arange(every_m, distance[-1] + 1e-9, every_m)
        ends = np.searchsorted(distance, marks - 1e-9) + 1
    return np.unique(np.concatenate([ends, [count]]).astype(np.int64))
