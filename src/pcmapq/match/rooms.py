"""Rooms matched one to one by overlap, and what became of each unmatched one.

Two label rasters on one grid (0 no room, room k at k + 1): the truth's rooms and the map's.
Their overlaps (cells shared) give each pair's IoU; one assignment (scipy
``linear_sum_assignment``) maximises the summed IoU, and a pair counts as matched at an IoU of
at least ``min_iou``. A room left over is:

- **merged**: a map room holds at least ``most`` of each of two or more truth rooms, each of
  them at least ``PIECE`` (a tenth) of the map room (a wall or door the map lacks joined
  them): those truth rooms and that map room; a smaller truth room the map left open to a
  room (a closet whose walls it lacks) is missing, and the room may match;
- **split**: at least two map rooms lie each for at least ``most`` of their own cells within
  one truth room and hold each at least ``PIECE`` (a tenth) of it (the map put a wall or a
  door where the truth has none): that truth room and those map rooms; a smaller pocket the
  map closed off inside it is an extra room;
- **missing** (a truth room) or **extra** (a map room) otherwise.

Merged and split rooms are left out of the assignment: a map room over two truth rooms is not
a match of either, even at an IoU of 0.5.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from pcmapq.features.base import Features
from pcmapq.features.rooms import overlap, room_overlap

__all__ = ["EXTRA", "FOUND", "MATCHED", "MERGED", "MISSING", "SPLIT", "UNJUDGED", "UNSEEN",
           "WRONG", "RoomMatch", "door_table", "match", "overlap", "room_table"]

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
    o = room_overlap(truth, map_, most)
    i, j = linear_sum_assignment(-o.usable)
    keep = o.usable[i, j] >= min_iou
    truth_of_map = np.full(o.shared.shape[1], -1)
    truth_of_map[j[keep]] = i[keep]

    truth_status = np.full(o.shared.shape[0], MISSING, dtype=object)
    map_status = np.full(o.shared.shape[1], EXTRA, dtype=object)
    truth_status[o.split] = SPLIT
    truth_status[o.merged] = MERGED
    map_status[o.merging] = MERGED
    map_status[o.pieces] = SPLIT
    truth_status[i[keep]] = MATCHED
    map_status[j[keep]] = MATCHED
    return RoomMatch(o.shared, o.iou, truth_of_map, truth_status.astype(str),
                     map_status.astype(str))


#: The status of a truth room the quality does not count (less than ``min_seen`` of it inside
#: the map's footprint), whether or not a map room overlaps it.
UNSEEN = "unseen"


def room_table(truth: Features, map_: Features) -> dict:
    """The rooms of the rooms detector's two sides as JSON (lists of plain numbers, metres,
    square metres, truth frame): per truth room its centroid, area, status (``unseen``: not
    counted, the map saw too little of it), and for one paired with a map room its IoU, the
    map room's area less its own and the centroids' offset; per map room its centroid, area,
    status and matched truth room (index, or None); each side's doors (:func:`door_table`);
    and the count of each status."""
    if truth.labels is None or map_.labels is None or truth.labels.shape != map_.labels.shape:
        return {"truth": [], "map": [], "doors": {"truth": [], "map": []}, "counts": {}}
    found = match(truth.labels, map_.labels)
    t_status = np.where(~truth.strong, UNSEEN, found.truth_status)
    map_of_truth = _inverse(found.truth_of_map, len(truth))
    rows = []
    for k in range(len(truth)):
        row = {"x_m": float(truth.xy[k, 0]), "y_m": float(truth.xy[k, 1]),
               "area_m2": float(truth.strength[k]), "status": str(t_status[k])}
        j = map_of_truth[k]
        if j >= 0:
            row.update(iou=float(found.iou[k, j]),
                       area_error_m2=float(map_.strength[j] - truth.strength[k]),
                       offset_m=float(np.hypot(*(map_.xy[j] - truth.xy[k]))))
        rows.append(row)
    maps = [{"x_m": float(map_.xy[j, 0]), "y_m": float(map_.xy[j, 1]),
             "area_m2": float(map_.strength[j]), "status": str(found.map_status[j]),
             "truth": None if found.truth_of_map[j] < 0 else int(found.truth_of_map[j])}
            for j in range(len(map_))]
    truth_doors, map_doors = door_table(truth, map_, found.truth_of_map)
    statuses = [*(f"truth {s}" for s in t_status), *(f"map {s}" for s in found.map_status),
                *(f"truth door {d['status']}" for d in truth_doors),
                *(f"map door {d['status']}" for d in map_doors)]
    return {"truth": rows, "map": maps, "doors": {"truth": truth_doors, "map": map_doors},
            "counts": {s: statuses.count(s) for s in sorted(set(statuses))}}


#: A door's status: found in both, missing from the map, connecting other rooms than any
#: truth door, or between rooms that are not both matched (nothing to compare).
FOUND, WRONG, UNJUDGED = "found", "wrong", "not judged"


def door_table(truth: Features, map_: Features, truth_of_map: np.ndarray
               ) -> tuple[list[dict], list[dict]]:
    """Each side's doors as JSON rows (``rooms``: the two rooms' indices, ``x_m``, ``y_m``,
    ``width_m``, ``status``). A truth door between two matched rooms is ``found`` when a map
    door joins their map rooms, else ``missing``; a map door between two matched rooms is
    ``found`` when a truth door joins their truth rooms, else ``wrong`` (the map connects
    rooms the truth does not); a door with a room not matched on its side is ``not judged``."""
    def rows(doors: np.ndarray | None) -> list[dict]:
        if doors is None:
            return []
        return [{"rooms": [int(a), int(b)], "x_m": float(x), "y_m": float(y),
                 "width_m": float(w)} for a, b, x, y, w in doors]

    t_rows, m_rows = rows(truth.doors), rows(map_.doors)
    map_of_truth = _inverse(truth_of_map, len(truth))
    truth_pairs = {tuple(r["rooms"]) for r in t_rows}
    map_pairs = {tuple(r["rooms"]) for r in m_rows}
    for r in t_rows:
        a, b = (int(map_of_truth[k]) for k in r["rooms"])
        r["status"] = UNJUDGED if min(a, b) < 0 else \
            FOUND if (min(a, b), max(a, b)) in map_pairs else MISSING
    for r in m_rows:
        a, b = (int(truth_of_map[k]) for k in r["rooms"])
        r["status"] = UNJUDGED if min(a, b) < 0 else \
            FOUND if (min(a, b), max(a, b)) in truth_pairs else WRONG
    return t_rows, m_rows


def _inverse(truth_of_map: np.ndarray, truths: int) -> np.ndarray:
    """(truths,) the map room matched to each truth room, -1 for none: the inverse of
    ``truth_of_map`` (each map room's truth room, -1 for none)."""
    map_of_truth = np.full(truths, -1)
    paired = np.flatnonzero(truth_of_map >= 0)
    map_of_truth[truth_of_map[paired]] = paired
    return map_of_truth
