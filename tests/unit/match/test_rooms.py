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


def test_a_pocket_closed_off_inside_a_room_is_extra_and_the_room_matched():
    """A map room of 4 cells inside a truth room of 100 (a cupboard's outline): no split; at 12
    cells (more than a tenth of the room) it is a piece, and the room split."""
    truth = strips(10, 8)
    for size, split in ((4, False), (12, True)):
        map_ = truth.copy()
        map_[map_ == 2] = 3
        map_[:size // 2, :2] = 2  # the pocket, in the first room's corner
        found = match(truth, map_)
        if split:
            assert list(found.truth_status) == [SPLIT, MATCHED]
            assert list(found.map_status) == [SPLIT, SPLIT, MATCHED]
        else:
            assert list(found.truth_status) == [MATCHED, MATCHED]
            assert list(found.map_status) == [MATCHED, EXTRA, MATCHED]


def test_a_closet_the_map_joined_to_a_room_is_missing_and_the_room_matched():
    """A truth closet of 1 column (10 cells) beside a room of 10 columns, the map's one room
    over both (110 cells): the closet is less than a tenth of it, so no merger: the room
    matches (IoU 100/110) and the closet is missing. A closet of 2 columns (20 of 120 cells,
    a sixth) is a room the map merged, the room with it."""
    for width, merged in ((1, False), (2, True)):
        truth, map_ = strips(10, width, 8), strips(10 + width, 8)
        found = match(truth, map_)
        if merged:
            assert list(found.truth_status) == [MERGED, MERGED, MATCHED]
            assert list(found.map_status) == [MERGED, MATCHED]
        else:
            assert list(found.truth_status) == [MATCHED, MISSING, MATCHED]
            assert list(found.map_status) == [MATCHED, MATCHED]


def test_a_room_not_entered_is_missing_and_a_room_outside_the_truth_is_extra():
    truth, map_ = strips(5, 5, -5), strips(5, -5, 5)
    found = match(truth, map_)
    assert list(found.truth_status) == [MATCHED, MISSING]
    assert list(found.map_status) == [MATCHED, EXTRA]


def features_of(labels: np.ndarray, strong: np.ndarray | None = None):
    """Rooms as the detector gives them: centroids (cells as metres), areas, labels."""
    from pcmapq.features.base import Features

    n = int(labels.max())
    rows, cols = np.indices(labels.shape)
    cells = np.bincount(labels.ravel(), minlength=n + 1)[1:]
    xy = np.column_stack([np.bincount(labels.ravel(), cols.ravel(), n + 1)[1:],
                          np.bincount(labels.ravel(), rows.ravel(), n + 1)[1:]]) / cells[:, None]
    return Features(xy=xy, strength=cells.astype(float),
                    strong=np.ones(n, bool) if strong is None else strong, labels=labels)


def test_the_room_table_says_what_became_of_every_room():
    from pcmapq.match.rooms import UNSEEN, room_table

    truth = features_of(strips(5, 5, 8, 4), strong=np.array([True, True, True, False]))
    table = room_table(truth, features_of(strips(10, 8, -4)))
    assert [r["status"] for r in table["truth"]] == [MERGED, MERGED, MATCHED, UNSEEN]
    assert [r["status"] for r in table["map"]] == [MERGED, MATCHED]
    assert table["map"][1]["truth"] == 2 and table["map"][0]["truth"] is None
    assert table["truth"][2]["iou"] == 1.0 and table["truth"][2]["offset_m"] == 0.0
    assert "iou" not in table["truth"][0]
    assert table["counts"] == {"map matched": 1, "map merged": 1, "truth matched": 1,
                               "truth merged": 2, "truth unseen": 1}


def test_a_room_the_map_saw_too_little_of_is_unseen_even_when_a_map_room_overlaps_it():
    """Its status agrees with the quality, which leaves it out; its fit is still given, and the
    map room that overlaps it is matched (the precision counts it so)."""
    from pcmapq.match.rooms import UNSEEN, room_table

    truth = features_of(strips(8, 8), strong=np.array([True, False]))
    table = room_table(truth, features_of(strips(8, 8)))
    assert [r["status"] for r in table["truth"]] == [MATCHED, UNSEEN]
    assert table["truth"][1]["iou"] == 1.0
    assert [r["status"] for r in table["map"]] == [MATCHED, MATCHED]
    assert table["counts"] == {"map matched": 2, "truth matched": 1, "truth unseen": 1}


def test_a_pocket_or_a_room_mostly_elsewhere_is_no_room_drawn_over_a_truth_room():
    """A map room drawn over a truth room is a piece of it or a room that merged it with
    another (holding most of each); a pocket, or a room holding less than half of it, is
    not."""
    from pcmapq.features.rooms import drawn

    truth = features_of(strips(10, 10))
    pocket = np.zeros_like(truth.labels)
    pocket[:2, :4] = 1  # 8 cells of the first room's 100
    assert drawn(truth, features_of(pocket)).tolist() == [False, False]
    # 100 of its 140 cells in the second room, 40 in the first: less than half of the first
    across = features_of(strips(-6, 14))
    assert drawn(truth, across).tolist() == [False, True]
    # 100 of its 160 cells in the second room, 60 in the first: it merged the two rooms
    merger = features_of(strips(-4, 16))
    assert drawn(truth, merger).tolist() == [True, True]
    none = truth.labels * 0
    assert drawn(truth, features_of(none)).tolist() == [False, False]
