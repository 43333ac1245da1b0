"""Rooms matched one to one by overlap, and what became of each unmatched one.

Two label rasters on one grid (0 no room, room k at k + 1): the truth's rooms and the map's.
Their overlaps (cells shared) give each pair's IoU; one assignment (scipy
``linear_sum_assignment``) maximises the summed IoU, and a pair counts as matched at an IoU of
at least ``min_iou``. A room left over is:

- **merged**: a map room holds at least ``most`` of each of two or more truth rooms (a wall
  or door the map lacks joined them): those truth rooms and that map room;
- **split**: at least two map rooms lie each for at least ``most`` of their own cells within
  one truth room (the map put a wall or a door where the truth has none): that truth room and
  those map rooms;
- **missing** (a truth room) or **extra** (a map room) otherwise.

Merged and split rooms are left out of the assignment: a map room over two truth rooms is not
a match of either, even at an IoU of 0.5.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from pcmapq.features.rooms import overlap

__all__ = ["EXTRA", "MATCHED", "MERGED", "MISSING", "SPLIT", "RoomMatch", "match", "overlap"]

#: Statuses of a truth room and of a map room.
MATCHED, MERGED, SPLIT, MISSING, EXTRA = "matched", "merged", "split", "missing", "extra"


@dataclass(frozen=True)
class RoomMatch:
    """Truth rooms T, map rooms M.

    overlap: (T, M) cells each pair shares. iou: (T, M) their IoU.
    truth_of_map: (M,) the truth room each map room is matched to, -1 for none.
    truth_status: (T,) and map_status: (M,) one of the module's statuses.
    """

    overlap: np.ndarray
    iou: np.ndarray
    truth_of_map: np.ndarray
    truth_status: np.ndarray
    map_status: np.ndarray

    @property
    def matched(self) -> int:
        """Matched pairs."""
        return int((self.truth_of_map >= 0).sum())


def match(truth: np.ndarray, map_: np.ndarray, min_iou: float = 0.5,
          most: float = 0.5) -> RoomMatch:
    """The rooms of ``map_`` matched to those of ``truth`` (label rasters, see
    :func:`overlap`), and the status of every room (module docstring)."""
    shared = overlap(truth, map_)
    t_cells = np.bincount(truth.ravel(), minlength=shared.shape[0] + 1)[1:]
    m_cells = np.bincount(map_.ravel(), minlength=shared.shape[1] + 1)[1:]
    union = t_cells[:, None] + m_cells[None, :] - shared
    iou = np.divide(shared, union, out=np.zeros(shared.shape), where=union > 0)
    of_truth = shared / np.maximum(t_cells, 1)[:, None]  # share of each truth room
    of_map = shared / np.maximum(m_cells, 1)[None, :]  # share of each map room
    merging = (of_truth >= most).sum(axis=0) >= 2  # (M,) holds most of 2+ truth rooms
    merged = (of_truth[:, merging] >= most).any(axis=1)
    piece = of_map >= most  # (T, M) the map room lies mostly in the truth room
    split = (piece.sum(axis=1) >= 2) & ~merged
    pieces = piece[split].any(axis=0) & ~merging
    # a merger, a split room and its pieces are what they are, not a match to one of them
    usable = np.where(merged[:, None] | split[:, None] | merging[None, :] | pieces[None, :],
                      0.0, iou)
    i, j = linear_sum_assignment(-usable)
    keep = usable[i, j] >= min_iou
    truth_of_map = np.full(shared.shape[1], -1)
    truth_of_map[j[keep]] = i[keep]

    truth_status = np.full(shared.shape[0], MISSING, dtype=object)
    map_status = np.full(shared.shape[1], EXTRA, dtype=object)
    truth_status[split] = SPLIT
    truth_status[merged] = MERGED
    map_status[merging] = MERGED
    map_status[pieces] = SPLIT
    truth_status[i[keep]] = MATCHED
    map_status[j[keep]] = MATCHED
    return RoomMatch(shared, iou, truth_of_map, truth_status.astype(str),
                     map_status.astype(str))
