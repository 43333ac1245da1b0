"""Partial maps: scored against the part of the truth they cover."""

from __future__ import annotations

import json
import re

import cv2
import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import PointMap
from pcmapq.io.writers import write_ros_map
from pcmapq.raster.seen import NO_VIEW, add_views
from pcmapq.settings import AlignmentConfig, FootprintConfig, MatchingConfig, Settings
from testkit import synth
from testkit.files import in_map_frame, write_cloud_map, write_image_map

#: Sub-rectangles of the 24 m x 16 m plan (x0, y0, x1, y1, metres) and map poses.
CUTS = [((-1, -1, 12.5, 17), Similarity2D(4.0, -6.0, np.radians(63.0))),      # west half
        ((9.5, 6.0, 25, 17), Similarity2D(-8.0, 3.0, np.radians(-128.0))),    # north-east third
        ((-1, -1, 25, 7.2), Similarity2D(15.0, 12.0, np.radians(201.0))),     # south rooms
        ((7.0, -1, 25, 11.0), Similarity2D(-3.0, -2.0, np.radians(17.0)))]    # a 45 % corner

#: Binary partial maps (black walls on white, no unknown value): 25-57 % of the plan, any pose.
#: No cut runs along a wall (the map would keep a sliver of it that the true share counts).
BINARY_CUTS = [((-1, -1, 7.8, 11.5), Similarity2D(-6.0, 5.0, np.radians(151.0))),  # 25 %
               ((15, -1, 25, 17), Similarity2D(3.0, -9.0, np.radians(288.0))),      # 32 %
               ((-1, 8.5, 25, 17), Similarity2D(7.0, 2.0, np.radians(138.0))),      # 46 %
               ((-1, -1, 16.5, 14), Similarity2D(-2.0, -4.0, np.radians(230.0)))]  # 57 %


#: Binary cuts of two plans that leave rooms open, off every wall as above: (plan seed, cut,
#: map pose), the cut a box (x0, y0, x1, y1) or a polygon (corners in order, plan frame).
OPEN_CUTS = [(0, (-1, -1, 10.5, 10.5), Similarity2D(2.0, 3.0, np.radians(40.0))),     # 34 %
             (1, (10.4, 3.0, 25, 17), Similarity2D(3.0, -9.0, np.radians(288.0))),     # 35 %
             (1, (-1, -1, 10.5, 8.0), Similarity2D(-3.0, 7.0, np.radians(322.0))),     # 25 %
             (0, ((-1, -1), (14, -1), (2, 17), (-1, 17)),                              # 39 %
              Similarity2D(7.0, 2.0, np.radians(138.0))),
             (1, ((-1, -1), (14, -1), (14, 6), (6, 6), (6, 17), (-1, 17)),             # an L, 44 %
              Similarity2D(-5.0, 4.0, np.radians(71.0))),
             (0, ((-1, -1), (25, -1), (25, 7.8), (9, 7.8), (9, 2.5), (5.5, 2.5),       # a U, 49 %
                  (5.5, 7.8), (-1, 7.8)), Similarity2D(6.0, 1.0, np.radians(197.0)))]


def true_share(plan: np.ndarray, cut) -> float:
    """Share of the truth's wall cells inside ``cut``: a box (x0, y0, x1, y1) or a polygon
    ((M, 2) corners in order), plan frame, metres."""
    from matplotlib.path import Path

    grid = synth.plan_grid(plan, 0.05)
    xy = grid.cell_centres(synth.render(plan, grid) == synth.OCCUPIED)
    if np.ndim(cut) == 2:
        return float(np.mean(Path(np.asarray(cut, dtype=np.float64)).contains_points(xy)))
    x0, y0, x1, y1 = cut
    return float(np.mean((xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)))


def unjudged_rooms(name: str, det) -> bool:
    """Rooms with no truth room wholly inside the footprint: nothing to count (a room the
    part saw only in part cannot be judged), so no quality."""
    return name == "rooms" and det.matching.truth_features == 0 and det.matching.quality is None


def write_partial_image(plan, box, tf: Similarity2D, path):
    """The plan seen in the map frame, with everything outside ``box`` (truth frame) unknown."""
    segments = in_map_frame(plan, tf)
    grid = synth.plan_grid(segments, 0.05)
    img = synth.render(segments, grid)
    x0, y0, x1, y1 = box
    corners = tf.inverse().apply(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]))
    mask = np.zeros(grid.shape, np.uint8)
    cv2.fillConvexPoly(mask, np.round(grid.xy_to_pixels(corners)).astype(np.int32), 1)
    img[mask == 0] = synth.UNKNOWN
    return write_ros_map(path, img, 0.05, grid.origin[:2])


def write_binary_partial(plan, box, tf: Similarity2D, path):
    """The plan's walls inside ``box`` (truth frame; or a polygon, (M, 2) corners) seen in the
    map frame, black on white."""
    img, grid = (synth.binary_cut(plan, np.asarray(box), tf) if np.ndim(box) == 2 else
                 synth.binary_partial(plan, box, tf))
    return write_ros_map(path, img, 0.05, grid.origin[:2])


@pytest.mark.parametrize(("box", "tf"), CUTS)
def test_partial_image_map(plan, truth_png, tmp_path, box, tf):
    share = true_share(plan, box)
    assert 0.3 <= share <= 0.62
    result = evaluate(write_partial_image(plan, box, tf, tmp_path / "part.png"), truth_png)
    assert result.footprint_rule == "known"  # its unknown cells say what it did not observe
    got = result.transform
    assert np.hypot(got.tx - tf.tx, got.ty - tf.ty) < 0.1
    assert abs(result.overlap.coverage - share) < 0.1, (result.overlap.coverage, share)
    for name, det in result.detectors.items():
        assert unjudged_rooms(name, det) or det.matching.quality >= 0.85, \
            (name, det.matching.quality)


@pytest.mark.parametrize(("box", "tf"), CUTS)
def test_partial_cloud_map(plan, truth_png, tmp_path, box, tf):
    share = true_share(plan, box)
    pts = synth.wall_points(plan, 0.02, noise=0.01, seed=3)
    x0, y0, x1, y1 = box
    pts = pts[(pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)]
    result = evaluate(write_cloud_map(tf.inverse().apply(pts), tmp_path / "part.npy"), truth_png)
    assert abs(result.overlap.coverage - share) < 0.1, (result.overlap.coverage, share)
    for name, det in result.detectors.items():
        assert unjudged_rooms(name, det) or det.matching.quality >= 0.85, \
            (name, det.matching.quality)


def test_full_map_covers_the_truth(plan, truth_png, tmp_path):
    tf = Similarity2D(2.0, 1.0, np.radians(30.0))
    pts = synth.wall_points(in_map_frame(plan, tf), 0.02, noise=0.01)
    result = evaluate(write_cloud_map(pts, tmp_path / "full.npy"), truth_png)
    assert result.overlap.coverage >= 0.95


def test_full_flag_scores_against_the_whole_truth(plan, truth_png, tmp_path):
    box, tf = CUTS[0]
    path = write_partial_image(plan, box, tf, tmp_path / "part.png")
    part = evaluate(path, truth_png)
    whole = evaluate(path, truth_png, Settings(footprint=FootprintConfig(full=True)))
    for name in part.detectors:
        q_part = part.detectors[name].matching.quality
        q_whole = whole.detectors[name].matching.quality
        assert q_whole < 0.75 * q_part, (name, q_whole, q_part)


@pytest.mark.parametrize(("box", "tf"), BINARY_CUTS)
def test_binary_partial_image_map(plan, truth_png, tmp_path, box, tf):
    """A binary image has no unknown cells: its footprint is the area its walls enclose."""
    share = true_share(plan, box)
    assert 0.24 <= share <= 0.6
    result = evaluate(write_binary_partial(plan, box, tf, tmp_path / "part.png"), truth_png)
    assert result.footprint_rule == "walls"
    got = result.transform
    assert np.hypot(got.tx - tf.tx, got.ty - tf.ty) < 0.1
    assert abs(result.overlap.coverage - share) < 0.1, (result.overlap.coverage, share)
    for name, det in result.detectors.items():
        assert unjudged_rooms(name, det) or det.matching.quality >= 0.85, \
            (name, det.matching.quality)


@pytest.mark.parametrize(("seed", "cut", "tf"), OPEN_CUTS)
def test_binary_cut_open_coverage_is_the_share_it_kept(seed, cut, tf, tmp_path):
    """A binary map cut from a plan by a box or a polygon (an L, a U) through its rooms: the
    area its walls enclose, closed and grown, ends at the cut, rooms cut open or not, so
    coverage is the share of the truth's walls the cut kept, and each quality stays high."""
    plan = synth.building_plan(seed)
    truth = write_image_map(plan, tmp_path / "truth.png")
    share = true_share(plan, cut)
    assert 0.24 <= share <= 0.5
    result = evaluate(write_binary_partial(plan, cut, tf, tmp_path / "part.png"), truth)
    assert result.footprint_rule == "walls"
    got = result.transform
    assert np.hypot(got.tx - tf.tx, got.ty - tf.ty) < 0.1
    assert abs(result.overlap.coverage - share) < 0.05, (result.overlap.coverage, share)
    for name, det in result.detectors.items():
        assert unjudged_rooms(name, det) or det.matching.quality >= 0.9, \
            (name, det.matching.quality)


def test_known_footprint_of_a_binary_map_counts_its_whole_rectangle(plan, truth_png, tmp_path):
    """--footprint known on a binary image: every cell is known, so the truth's walls anywhere
    in its rectangle count as missing (the behaviour before the walls rule)."""
    box, tf = BINARY_CUTS[2]
    share = true_share(plan, box)
    path = write_binary_partial(plan, box, tf, tmp_path / "part.png")
    walls = evaluate(path, truth_png)
    # the truth's walls across the rectangle lie far from the map, so the confidence that the
    # map shows this place is low with these footprints: force them
    known = evaluate(path, truth_png, Settings(footprint=FootprintConfig(rule="known"),
                                               alignment=AlignmentConfig(force=True)))
    everything = evaluate(path, truth_png, Settings(footprint=FootprintConfig(rule="all"),
                                                    alignment=AlignmentConfig(force=True)))
    assert known.footprint_rule == "known" and everything.footprint_rule == "all"
    assert known.overlap.coverage > share + 0.1, (known.overlap.coverage, share)
    assert everything.overlap.coverage >= known.overlap.coverage - 0.01
    for name in walls.detectors:
        assert known.detectors[name].matching.quality < walls.detectors[name].matching.quality
    assert json.loads(known.to_json())["footprint"] == "known"


def test_all_footprint_of_an_image_with_unknown_cells(plan, truth_png, tmp_path):
    """--footprint all: the image's whole rectangle, unknown cells included."""
    box, tf = CUTS[1]
    path = write_partial_image(plan, box, tf, tmp_path / "part.png")
    known = evaluate(path, truth_png, Settings(matching=MatchingConfig(detectors=("harris",))))
    whole = evaluate(path, truth_png, Settings(matching=MatchingConfig(detectors=("harris",)),
                                               footprint=FootprintConfig(rule="all"),
                                               # low recall across the rectangle
                                               alignment=AlignmentConfig(force=True)))
    assert known.footprint_rule == "known"
    assert whole.overlap.coverage > known.overlap.coverage + 0.3


def test_cloud_has_no_known_cells(plan, truth_png, tmp_path):
    pts = synth.wall_points(plan, 0.05)
    path = write_cloud_map(pts, tmp_path / "cloud.npy")
    with pytest.raises(InputError, match="cloud.npy: a point cloud has no known cells"):
        evaluate(path, truth_png, Settings(footprint=FootprintConfig(rule="known"),
                                           matching=MatchingConfig(detectors=("harris",))))
    result = evaluate(path, truth_png, Settings(footprint=FootprintConfig(rule="all"),
                                                matching=MatchingConfig(detectors=("harris",))))
    assert result.footprint_rule == "all" and result.overlap.coverage >= 0.99


def test_cli_footprint_option(plan, truth_png, tmp_path):
    from typer.testing import CliRunner

    from pcmapq.cli import app

    box, tf = BINARY_CUTS[0]
    path = str(write_binary_partial(plan, box, tf, tmp_path / "part.png"))
    runner = CliRunner()
    res = runner.invoke(app, ["eval", path, str(truth_png), "--detectors", "harris",
                              "--json", str(tmp_path / "r.json")])
    assert res.exit_code == 0, res.output
    assert re.search(r"^footprint +walls, coverage", res.output, flags=re.M), res.output
    assert json.loads((tmp_path / "r.json").read_text())["footprint"] == "walls"
    res = runner.invoke(app, ["eval", path, str(truth_png), "--footprint", "everything"])
    assert res.exit_code == 2 and "--footprint" in res.output
    cloud = str(write_cloud_map(synth.wall_points(plan, 0.1), tmp_path / "cloud.npy"))
    res = runner.invoke(app, ["eval", cloud, str(truth_png), "--footprint", "known"])
    assert res.exit_code == 2 and "Traceback" not in res.output
    assert "cloud.npy: a point cloud has no known cells" in res.output


def test_seen_footprint_counts_no_map_feature_outside_it(plan, truth_png):
    """A map of the whole plan that saw only its west half (a ``seen`` lattice): a box of
    clutter the truth lacks counts as extra inside the half it saw, and not at all in the half
    it did not (outside, its cells are not in the footprint); ``walls`` counts both."""
    west = np.array([[[-1.0, -1.0], [11.0, -1.0], [11.0, 17.0], [-1.0, 17.0]]])
    seen = add_views(NO_VIEW, west)
    walls = synth.wall_points(plan, 0.02, noise=0.01, seed=3)

    def scored(boxes: list[tuple[float, float]], rule: str):
        points = np.concatenate([walls, synth.wall_points(synth.boxes(boxes, 0.6), 0.02)])
        cloud = PointMap(truth_png, np.column_stack([points, np.zeros(len(points))]), False,
                         seen=seen)
        settings = Settings(alignment=AlignmentConfig(enabled=False),
                            footprint=FootprintConfig(rule=rule))
        return {name: d.matching for name, d in evaluate(cloud, truth_png, settings)
                .detectors.items()}

    inside, outside = (2.5, 2.0), (16.0, 2.0)  # in a room of each half, over 1.3 m from walls
    bare = scored([], "seen")
    for name, far in scored([outside], "seen").items():
        assert (far.map_features, far.matched_map) == (bare[name].map_features,
                                                       bare[name].matched_map), name
    near = scored([inside], "seen")
    assert sum(m.map_features - m.matched_map for m in near.values()) > \
        sum(m.map_features - m.matched_map for m in bare.values())
    counted = scored([], "walls")
    assert sum(m.map_features for m in scored([outside], "walls").values()) > \
        sum(m.map_features for m in counted.values())
