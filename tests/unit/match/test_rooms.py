"""Rooms matched one to one by IoU, and the status of the others, on labels with known
answers."""

from __future__ import annotations

import numpy as np

from pcmapq.match.rooms import EXTRA, MATCHED, MERGED, MISSING, SPLIT, match, overlap


def strips(*widths: int, height: int = 10) -> np.ndarray:
    """Labels of rooms side by side, ``widths`` columns each, numbered from 1 (0: a width
    given as negative, a gap)."""
    cols, label = [], 0
    for w in widths:
        if w < 0:
            cols.append(np.zeros(-w, int))
        else:
            label += 1
            cols.append(np.full(w, label))
    return np.tile(np.concatenate(cols), (height, 1))


def test_overlap_counts_shared_cells():
    truth, map_ = strips(4, 6), strips(5, 5)
    np.testing.assert_array_equal(overlap(truth, map_), [[40, 0], [10, 50]])


def test_the_same_rooms_all_match():
    rooms = strips(5, 7, 3)
    found = match(rooms, rooms)
    assert list(found.truth_status) == [MATCHED] * 3
    assert list(found.map_status) == [MATCHED] * 3
    np.testing.assert_array_equal(found.truth_of_map, [0, 1, 2])


def test_a_missing_wall_merges_two_truth_rooms():
    truth, map_ = strips(5, 5, 8), strips(10, 8)
    found = match(truth, map_)
    assert list(found.truth_status) == [MERGED, MERGED, MATCHED]
    assert list(found.map_status) == [MERGED, MATCHED]


def test_an_extra_wall_splits_a_truth_room():
    truth, map_ = strips(10, 8), strips(4, 6, 8)
    found = match(truth, map_)
    # the larger piece would match at IoU 0.6: a split room is no match
    assert list(found.truth_status) == [SPLIT, MATCHED]
    assert list(found.map_status) == [SPLIT, SPLIT, MATCHED]


def test_a_room_not_entered_is_missing_and_a_room_outside_the_truth_is_extra():
    truth, map_ = strips(5, 5, -5), strips(5, -5, 5)
    found = match(truth, map_)
    assert list(found.truth_status) == [MATCHED, MISSING]
    assert list(found.map_status) == [MATCHED, EXTRA]
