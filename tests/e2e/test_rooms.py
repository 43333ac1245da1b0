"""The rooms detector through the whole evaluation: a plan against a map of it that lacks
one wall reports those two rooms merged, every other room matched, and draws them."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.results.result import Result
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from testkit import synth
from testkit.files import write_image_map

PLAN = synth.building_plan(0)
#: The wall between the two rooms of the lower row at x = 8.03 m.
WALL = 5


@pytest.fixture(scope="module")
def result(tmp_path_factory) -> Result:
    folder = tmp_path_factory.mktemp("rooms")
    truth = write_image_map(PLAN, folder / "truth.png")
    seen = write_image_map(np.delete(PLAN, WALL, axis=0), folder / "map.png")
    return evaluate(seen, truth, Settings(matching=MatchingConfig(detectors=("rooms",))))


def test_a_wall_the_map_lacks_merges_its_two_rooms_and_nothing_else(result):
    rooms = result.rooms
    merged = [r for r in rooms["truth"] if r["status"] == "merged"]
    assert len(merged) == 2
    assert sorted(round(r["x_m"]) for r in merged) == [6, 11]  # either side of x = 8.03 m
    assert all(r["status"] == "matched" for r in rooms["truth"] if r not in merged)
    assert [r["status"] for r in rooms["map"]].count("merged") == 1
    assert rooms["counts"]["truth merged"] == 2
    m = result.detectors["rooms"].matching
    assert m.truth_features - m.matched == 2 and m.precision == pytest.approx(
        (m.map_features - 1) / m.map_features)
    matched = [r for r in rooms["truth"] if r["status"] == "matched"]
    assert all(r["iou"] > 0.9 and r["offset_m"] < 0.1 for r in matched)


def test_the_json_keeps_the_rooms_and_the_picture_shows_them(result, tmp_path):
    from pcmapq.report.plot import vectorial_figure

    back = Result.from_json(result.to_json())
    assert back.rooms == result.to_dict()["rooms"]
    fig = vectorial_figure(result)
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()] + \
        [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert "room merged" in labels and "room matched" in labels


def test_a_moved_wall_changes_the_two_rooms_beside_it_by_the_area_it_swept(tmp_path):
    """The wall at x = 8.03 m moved 0.5 m east: the room west of it grows by 0.5 m times the
    wall's length, the room east of it shrinks by as much, every room stays matched and the
    others keep their area within 0.5 m^2 (the alignment may shift the map by a 0.05 m
    cell)."""
    truth = write_image_map(PLAN, tmp_path / "truth.png")
    seen = write_image_map(synth.move_wall(PLAN, WALL, (0.5, 0.0)), tmp_path / "map.png")
    rooms = evaluate(seen, truth, Settings(matching=MatchingConfig(detectors=("rooms",)),
                                           alignment=AlignmentConfig(force=True))).rooms
    swept = 0.5 * float(np.hypot(*(PLAN[WALL, 2:] - PLAN[WALL, :2])))
    assert all(r["status"] == "matched" for r in rooms["truth"])
    error = {round(r["x_m"]): r["area_error_m2"] for r in rooms["truth"]}
    assert error.pop(6) == pytest.approx(swept, abs=0.3)  # west of x = 8.03 m
    assert error.pop(11) == pytest.approx(-swept, abs=0.3)  # east of it
    assert all(abs(e) < 0.5 for e in error.values()), (error, swept)


@pytest.fixture(scope="module")
def doors(tmp_path_factory) -> Result:
    """The map closes the lower-left room's door (x 1.24-2.14 m at y = 6.72 m) and opens a
    door of its own in the wall at x = 4.91 m (y 2-3 m)."""
    folder = tmp_path_factory.mktemp("doors")
    truth = write_image_map(PLAN, folder / "truth.png")
    walls = np.vstack([np.delete(PLAN, 4, axis=0),
                       [[1.24, 6.72, 2.14, 6.72], [4.91, 0.0, 4.91, 2.0],
                        [4.91, 3.0, 4.91, 6.72]]])
    seen = write_image_map(walls, folder / "map.png")
    return evaluate(seen, truth, Settings(matching=MatchingConfig(detectors=("rooms",))))


def test_a_door_closed_is_missing_and_a_door_the_plan_lacks_is_wrong(doors):
    rooms = doors.rooms
    assert all(r["status"] == "matched" for r in rooms["truth"])
    missing = [d for d in rooms["doors"]["truth"] if d["status"] == "missing"]
    assert len(missing) == 1 and abs(missing[0]["x_m"] - 1.7) < 0.3 \
        and abs(missing[0]["y_m"] - 6.72) < 0.3
    wrong = [d for d in rooms["doors"]["map"] if d["status"] == "wrong"]
    assert len(wrong) == 1 and abs(wrong[0]["x_m"] - 4.91) < 0.3 \
        and 2.0 <= wrong[0]["y_m"] <= 3.0
    assert rooms["counts"]["truth door found"] == len(rooms["doors"]["truth"]) - 1
    assert "truth door not judged" not in rooms["counts"]


def test_doors_of_merged_rooms_are_not_judged(result):
    judged = {d["status"] for d in result.rooms["doors"]["truth"]}
    assert "not judged" in judged and "missing" not in judged


def test_the_reports_map_tells_each_rooms_fit_on_hover(result):
    from pcmapq.report.viewer import viewer_html

    page = viewer_html(result, 10.0)
    # every truth room (matched or missing), and the map room over two of them (extra)
    assert page.count("data-room=") == len(result.rooms["truth"]) + 1
    assert "matched; IoU" in page and "merged" in page


@pytest.mark.skipif(shutil.which("chromium") is None, reason="Debian's chromium is not installed")
def test_hovering_a_room_in_chromium_tells_its_fit(result, tmp_path):
    """The whole report in headless Chromium: hovering a matched room's marker shows its
    number, area, status, IoU, area error and offset as the rooms' table has them; unticking
    the matched rooms hides them and nothing else."""
    from pcmapq.report.html import report_html
    from testkit.viewer import probed, selector

    det = result.detectors["rooms"]
    k = int(det.matching.truth_idx[0])
    row = result.rooms["truth"][k]
    (x, y) = det.truth_xy[k]
    out = probed(report_html(result), selector("rooms", "matched", x, y),
                 ("rooms", "matched"), tmp_path)
    assert out["hit"] and out["hoverShown"] == "block"
    assert f"truth room {k}: {row['area_m2']:.2f} m2, matched; IoU {row['iou']:.3f}" \
        in out["hover"], out["hover"]
    assert f"offset {row['offset_m']:.3f} m" in out["hover"], out["hover"]
    assert not any(out["toggledAfter"]) and all(out["othersAfter"])


def test_the_picture_draws_the_rooms_graph_with_its_wrong_and_missing_doors(doors):
    from matplotlib.collections import LineCollection

    from pcmapq.report.plot import vectorial_figure
    from pcmapq.report.rooms_layer import DOOR_COLOURS

    fig = vectorial_figure(doors)
    ax = fig.axes[0]
    dashed = [c for c in ax.collections if isinstance(c, LineCollection)
              and c.get_linestyle()[0][1] is not None]
    assert len(dashed) == 2 and sum(len(c.get_segments()) for c in dashed) == 2
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert {"door missing", "door wrong"} <= set(labels)
    assert DOOR_COLOURS["missing"] != DOOR_COLOURS["wrong"]
