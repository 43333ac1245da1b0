"""The pieces of ``pcmapq track`` with known answers: the scans' views and the ``seen``
footprint, when steps fall, the worst drop."""

from __future__ import annotations

from dataclasses import asdict

import numpy as np
import pytest

from pcmapq.core import memory
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.inputs import distinct_cells
from pcmapq.io.carmen import beam_angles
from pcmapq.raster.footprint import (
    footprint_rule,
    joined_readings,
    map_footprint,
    view_outlines,
)
from pcmapq.raster.seen import NO_VIEW, add_views, seen_on
from pcmapq.report.timeline import drop_words, timeline_html
from pcmapq.track.drop import MIN_DROP, worst_drop
from pcmapq.track.outputs import step_rows
from pcmapq.track.steps import step_ends, travelled
from pcmapq.track.timeline import Step

GRID = MetricGrid(0.05, (0.0, 0.0, 0.0), (200, 300))  # 15 m x 10 m


def view_cells(views: np.ndarray, transform: Similarity2D | None = None) -> np.ndarray:
    """GRID's cells the views (K, V, 2, map frame) cover, the map placed by ``transform``
    (default: as it is)."""
    return seen_on(add_views(NO_VIEW, views), transform or Similarity2D(), GRID)


def _room_scan(origin: np.ndarray, box: tuple[float, float, float, float],
               beams: int = 720) -> np.ndarray:
    """Endpoints (beams, 2) of a 360-degree scan from ``origin`` inside the axis-aligned room
    ``box`` (x0, y0, x1, y1), metres: the exact hits on its walls."""
    a = np.linspace(-np.pi, np.pi, beams, endpoint=False) + 1e-3
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    with np.errstate(divide="ignore"):
        tx = np.where(d[:, 0] > 0, (box[2] - origin[0]) / d[:, 0], (box[0] - origin[0]) / d[:, 0])
        ty = np.where(d[:, 1] > 0, (box[3] - origin[1]) / d[:, 1], (box[1] - origin[1]) / d[:, 1])
    return origin + np.minimum(tx, ty)[:, None] * d


def test_views_of_a_room_seen_from_inside_cover_the_room():
    """One 360-degree scan from inside a 6 m x 4 m room: its view is the room (up to the
    sectors' chords, less than a cell at these distances), nothing outside it."""
    box = (2.0, 3.0, 8.0, 7.0)
    origin = np.array([4.0, 5.0])
    hits = _room_scan(origin, box)
    views = view_outlines(origin[None], hits, np.zeros(len(hits), dtype=np.int64))
    assert views.shape == (1, 360, 2)
    seen = view_cells(views)
    centres = GRID.cell_centres(np.ones(GRID.shape, bool)).reshape(*GRID.shape, 2)
    inside = ((centres[..., 0] > box[0] + 0.1) & (centres[..., 0] < box[2] - 0.1)
              & (centres[..., 1] > box[1] + 0.1) & (centres[..., 1] < box[3] - 0.1))
    outside = ((centres[..., 0] < box[0] - 0.1) | (centres[..., 0] > box[2] + 0.1)
               | (centres[..., 1] < box[1] - 0.1) | (centres[..., 1] > box[3] + 0.1))
    assert seen[inside].all()
    assert not seen[outside].any()


def test_a_sector_without_readings_is_not_seen():
    """A half scan (readings only ahead, +x) sees the half of the room in front of it."""
    box = (2.0, 3.0, 8.0, 7.0)
    origin = np.array([5.0, 5.0])
    hits = _room_scan(origin, box)
    ahead = hits[hits[:, 0] > origin[0]]
    seen = view_cells(view_outlines(origin[None], ahead, np.zeros(len(ahead), np.int64)))
    xy = GRID.cell_centres(seen)
    assert xy[:, 0].min() > origin[0] - 0.1
    assert xy[:, 0].max() > box[2] - 0.1


def test_views_are_a_union_over_scans():
    """Two scans from two rooms see both rooms; the footprint 'seen' is that union grown by
    the margin."""
    a_box, b_box = (1.0, 1.0, 5.0, 5.0), (9.0, 2.0, 14.0, 8.0)
    a, b = np.array([3.0, 3.0]), np.array([11.0, 5.0])
    hits = np.vstack([_room_scan(a, a_box), _room_scan(b, b_box)])
    scan = np.repeat([0, 1], 720)
    views = view_outlines(np.stack([a, b]), hits, scan)
    seen = view_cells(views)
    one = view_cells(views[:1]) | view_cells(views[1:])
    assert (seen == one).all()
    grown = map_footprint("seen", np.zeros(GRID.shape, bool), GRID, 0.3, seen=seen)
    assert grown.sum() > seen.sum() and (grown | ~seen).all()


def test_views_added_step_by_step_fill_what_they_fill_at_once():
    """The lattice grown one view at a time (each growing it: the second room lies beyond
    the first's cells) holds exactly the cells of both views filled at once."""
    a, b = np.array([3.0, 3.0]), np.array([11.0, 5.0])
    hits = np.vstack([_room_scan(a, (1.0, 1.0, 5.0, 5.0)), _room_scan(b, (9.0, 2.0, 14.0, 8.0))])
    views = view_outlines(np.stack([a, b]), hits, np.repeat([0, 1], 720))
    first = add_views(NO_VIEW, views[:1])
    both, once = add_views(first, views[1:]), add_views(NO_VIEW, views)
    assert both.corner == once.corner and np.array_equal(both.cells, once.cells)
    assert first.cells.sum() < both.cells.sum()  # the first is not changed
    assert np.array_equal(add_views(first, views[1:]).cells, both.cells)


def test_the_seen_area_moves_with_the_map():
    """A room seen in the map's frame, the map turned by 90 degrees and shifted: the cells the
    truth's grid draws are those of the room where the transform puts it, up to a cell at its
    border."""
    box = (-3.0, -2.0, 3.0, 2.0)
    hits = _room_scan(np.array([-1.0, 0.5]), box)
    views = view_outlines(np.array([[-1.0, 0.5]]), hits, np.zeros(len(hits), np.int64))
    moved = view_cells(views, Similarity2D(7.5, 5.0, np.pi / 2))
    centres = GRID.cell_centres(np.ones(GRID.shape, bool)).reshape(*GRID.shape, 2)
    x, y = centres[..., 0] - 7.5, centres[..., 1] - 5.0  # the room is 4 m wide in x, 6 m in y
    inside = (np.abs(x) < 2.0 - 0.1) & (np.abs(y) < 3.0 - 0.1)
    outside = (np.abs(x) > 2.0 + 0.1) | (np.abs(y) > 3.0 + 0.1)
    assert moved[inside].all() and not moved[outside].any()


def test_joined_readings_are_those_drawing_a_wall_as_a_line():
    """CARMEN's 1-degree beams on a wall facing the scanner: at 5 m readings land 0.087 m
    apart and all but the two ends are joined; at 15 m (0.26 m apart, beyond 0.2 / (pi / 180)
    = 11.46 m) none is; along a wall 1 m to the side, readings more than 0.2 m apart are not.
    A scan's first reading is not joined to the previous scan's last."""
    angles = beam_angles(180)
    ahead = angles[np.abs(angles) < np.radians(20)]
    for distance, joined in ((5.0, True), (15.0, False)):
        hits = np.column_stack([np.full(len(ahead), distance), distance * np.tan(ahead)])
        got = joined_readings(hits, np.zeros(len(hits), np.int64), 0.2)
        assert not got[0] and not got[-1] and (got[1:-1] == joined).all()
    side = angles[(angles > np.radians(5)) & (angles < np.radians(80))]
    hits = np.column_stack([1.0 / np.tan(side), np.ones(len(side))])  # the wall y = 1
    gaps = np.hypot(*np.diff(hits, axis=0).T)
    got = joined_readings(hits, np.zeros(len(hits), np.int64), 0.2)
    assert (got[1:-1] == ((gaps[:-1] <= 0.2) & (gaps[1:] <= 0.2))).all()
    assert got.any() and not got.all()
    hits = np.column_stack([np.full(len(ahead), 5.0), 5.0 * np.tan(ahead)])
    two = np.concatenate([hits, hits])
    scan = np.repeat([0, 1], len(hits))
    assert np.array_equal(joined_readings(two, scan, 0.2),
                          np.tile(joined_readings(hits, scan[:len(hits)], 0.2), 2))
    for count in (0, 1):  # no neighbour, nothing joined
        assert not joined_readings(hits[:count], scan[:count], 0.2).any()
        assert len(joined_readings(hits[:count], scan[:count], 0.2)) == count


def test_the_seen_footprint_leaves_out_the_cells_of_readings_that_drew_no_wall():
    """Occupied cells outside the seen area (dots no view reaches) stay out of a ``seen``
    footprint, while ``walls`` and ``all`` take every occupied cell in."""
    seen = np.zeros(GRID.shape, bool)
    seen[50:100, 50:100] = True
    occupied = np.zeros(GRID.shape, bool)
    occupied[150, 250] = occupied[75, 100] = True
    footprint = map_footprint("seen", occupied, GRID, 0.3, seen=seen)
    assert not footprint[150, 250] and footprint[75, 100]
    assert footprint.sum() == map_footprint("seen", np.zeros_like(occupied), GRID, 0.3,
                                            seen=seen).sum()
    assert map_footprint("walls", occupied, GRID, 0.3)[150, 250]
    corner = np.array([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]])
    assert map_footprint("all", occupied, GRID, 0.3, rectangle=corner)[150, 250]


def test_footprint_rule_seen_needs_views():
    assert footprint_rule("auto", None, 0.0, views=True) == "seen"
    assert footprint_rule("auto", None, 0.0) == "walls"
    with pytest.raises(ValueError, match="'seen' needs the scans' poses"):
        footprint_rule("seen", None, 0.0)


def test_step_ends_every_scans_and_metres():
    """Every 20 scans of 50: 20, 40 and the last; every 1 m along a straight path of 0.25 m
    steps: the scans that reach 1, 2, 3 ... m."""
    assert step_ends(50, every=20).tolist() == [20, 40, 50]
    assert step_ends(40, every=20).tolist() == [20, 40]
    poses = np.tile(np.eye(4), (13, 1, 1))
    poses[:, 0, 3] = 0.25 * np.arange(13)  # 0 .. 3 m
    distance = travelled(poses)
    assert distance[-1] == pytest.approx(3.0)
    assert step_ends(13, every_m=1.0, distance=distance).tolist() == [5, 9, 13]
    with pytest.raises(ValueError):
        step_ends(13, every=2, every_m=1.0, distance=distance)


def _steps(values: list[float | None]) -> list[Step]:
    return [Step(i, 10 * (i + 1), None, float(i), {"precision": v},
                 "" if v is not None else "degenerate map") for i, v in enumerate(values)]


def test_worst_drop_starts_after_the_last_step_level_with_the_peak():
    """A plateau within the noise band, then a fall: the drop starts at the first step below
    the band; a step that could not be scored is skipped."""
    drop = worst_drop(_steps([None, 0.8, 0.9, 0.92, 0.91, 0.915, 0.84, 0.7, 0.6, 0.65]))
    assert drop is not None
    assert (drop.peak, drop.start, drop.low) == (3, 6, 8)
    assert drop.size == pytest.approx(0.32)
    assert drop.lasting == pytest.approx(0.27)  # step 9 came back to 0.65


def test_a_dip_the_map_recovers_from_is_no_drop():
    """A fall of 0.1 that later steps make up is no drop; one made up only in part is a drop
    of its full size, lasting what was never made up; the worst lasting one is reported."""
    assert worst_drop(_steps([0.9, 0.93, 0.83, 0.9, 0.95, 1.0])) is None
    drop = worst_drop(_steps([0.9, 0.9, 0.6, 0.7, 0.7]))
    assert (drop.peak, drop.start, drop.low) == (1, 2, 2)
    assert (drop.size, drop.lasting) == pytest.approx((0.3, 0.2))
    # a deep dip made up, then a shallower fall that lasts
    drop = worst_drop(_steps([0.9, 0.5, 0.9, 0.92, 0.8, 0.8]))
    assert (drop.peak, drop.start, drop.low) == (3, 4, 4)
    assert drop.lasting == pytest.approx(0.12)


def test_no_drop_in_a_rising_run_or_below_the_band():
    assert worst_drop(_steps([0.5, 0.6, 0.7, 0.8, 0.9, 1.0])) is None
    assert worst_drop(_steps([0.9, 0.9 - 0.9 * MIN_DROP, 0.9])) is None
    assert worst_drop(_steps([None, 0.9])) is None


def test_the_drop_in_words_says_how_far_later_steps_came_back():
    steps = _steps([0.9, 0.9, 0.6, 0.7, 0.65])
    words = drop_words(step_rows(steps), asdict(worst_drop(steps)))
    assert words == ("precision fell 0.300, from 0.900 at step 1 to 0.600 at step 2, and no "
                     "later step came back above 0.700; the fall starts at step 2 (2 m)")
    steps = _steps([0.9, 0.9, 0.8, 0.7])
    assert ("to 0.700 at step 3, the last step scored; the fall starts at step 2"
            in drop_words(step_rows(steps), asdict(worst_drop(steps))))


def test_distinct_cells_counts_cells_as_a_row_wise_unique():
    rng = np.random.default_rng(3)
    xy = np.vstack([rng.normal(size=(5000, 2)) * 3, rng.normal(size=(10, 2)) * 1e4])
    assert distinct_cells(xy) == len(np.unique(np.floor(xy / memory.WORKING_CELL), axis=0))


def test_the_report_of_a_run_without_a_drop_says_so():
    """No drop: the report shows the last step, says there was none and that the step could
    not be scored when it could not; the inputs are named."""
    rows = step_rows(_steps([0.8, 0.82, None]))
    page = timeline_html(rows, None, 2, None, None, command=None,
                         inputs={"run": "run.log", "poses": "est.txt", "truth": "truth.png"})
    assert "Step 2 (the last step; no drop): 30 of 30 scans" in page
    assert "no lasting drop of precision (none of at least 0.05)" in page
    assert "not scored: degenerate map" in page
    assert "<td>poses</td><td>est.txt</td>" in page


def test_the_3d_figures_of_a_3d_run_get_panels_of_their_own():
    """A run of two 3D clouds draws its planes' f1 and its AWD and largest 3D offset, each in
    a panel of its own; a 2D run's rows have no such column and no such panel."""
    from pcmapq.report.timeline import timeline_figure

    flat = [{"distance_m": float(d), "harris_quality": 0.5 + 0.1 * d} for d in range(3)]
    solid = [{**row, "planes_f1": 0.4, "plane_lines_f1": 0.2, "awd_m": 0.3 - 0.05 * d,
              "largest_offset_3d_m": 0.1 * d} for d, row in enumerate(flat)]
    titles = {name: [ax.get_title(loc="left") for ax in timeline_figure(rows, None).axes]
              for name, rows in (("flat", flat), ("solid", solid))}
    assert not any("3D" in t for t in titles["flat"])
    assert titles["solid"] == [*titles["flat"], *(t for t in titles["solid"] if "3D" in t)]
    assert len(titles["solid"]) == len(titles["flat"]) + 2
