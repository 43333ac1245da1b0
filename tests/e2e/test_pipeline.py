"""End-to-end behaviour on synthetic maps with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from testkit import synth
from testkit.files import in_map_frame, write_cloud_map, write_image_map

DETECTORS = ("harris", "hough", "sift")


def qualities(result) -> dict[str, float]:
    return {name: det.matching.quality for name, det in result.detectors.items()}


def test_map_equal_to_truth_scores_at_least_098(truth_png):
    result = evaluate(truth_png, truth_png)
    for name, q in qualities(result).items():
        assert q >= 0.98, (name, q)
    assert abs(result.transform.yaw_deg) < 0.5
    assert result.alignment.fitness > 0.95


RIGID = [(15.0, (3.0, -4.0)), (90.0, (-7.5, 2.0)), (172.0, (12.0, 9.0)), (-47.0, (-5.0, -11.0))]


def _check_recovered(result, tf: Similarity2D) -> None:
    got = result.transform
    assert np.hypot(got.tx - tf.tx, got.ty - tf.ty) < 0.1, got
    assert abs((got.yaw_deg - tf.yaw_deg + 180) % 360 - 180) < 0.5, got
    for name, q in qualities(result).items():
        assert q >= 0.9, (name, q)


@pytest.mark.parametrize(("yaw", "shift"), RIGID)
def test_rigid_image_map_is_recovered(plan, truth_png, tmp_path, yaw, shift):
    tf = Similarity2D(*shift, np.radians(yaw))
    path = write_image_map(in_map_frame(plan, tf), tmp_path / "map.png")
    _check_recovered(evaluate(path, truth_png), tf)


@pytest.mark.parametrize(("yaw", "shift"), RIGID)
def test_rigid_3d_cloud_is_recovered(plan, truth_png, tmp_path, yaw, shift):
    tf = Similarity2D(*shift, np.radians(yaw))
    cloud = synth.lidar_cloud(in_map_frame(plan, tf), spacing=0.07, seed=2)
    cloud[:, 2] += 1.3  # floor somewhere else than z = 0
    _check_recovered(evaluate(write_cloud_map(cloud, tmp_path / "scan.npy"), truth_png), tf)


#: The rows of the maps the ladders scored, by their segments' or points' bytes: the ladders
#: that start from the plan itself score it once.
SCORED: dict[tuple, dict[str, tuple[float, float, float]]] = {}


def _ladder(plan, truth_png, tmp_path, maps) -> list[dict[str, tuple[float, float, float]]]:
    """(quality, precision, f1) per detector for each step of a ladder of map files."""
    rows = []
    for i, segments_or_points in enumerate(maps):
        key = (segments_or_points.shape, segments_or_points.tobytes())
        if key not in SCORED:
            if segments_or_points.shape[1] == 4:
                path = write_image_map(segments_or_points, tmp_path / f"step{i}.png")
            else:
                path = write_cloud_map(segments_or_points, tmp_path / f"step{i}.npy")
            result = evaluate(path, truth_png, Settings(alignment=AlignmentConfig(force=True)))
            SCORED[key] = {n: (d.matching.quality, d.matching.precision, d.matching.f1)
                           for n, d in result.detectors.items()}
        rows.append(SCORED[key])
    return rows


def _falls(rows, column: int) -> None:
    """Each step scores below the one before on ``column`` (0 quality, 1 precision, 2 f1)."""
    for name in DETECTORS:
        values = [row[name][column] for row in rows]
        assert all(b < a for a, b in zip(values, values[1:], strict=False)), (name, column, values)


def test_ladder_missing_walls(plan, truth_png, tmp_path):
    rows = _ladder(plan, truth_png, tmp_path,
                   [synth.drop_walls(plan, f, seed=1) for f in (0.0, 0.15, 0.3, 0.5)])
    _falls(rows, 0)
    _falls(rows, 2)


def test_ladder_bend(plan, truth_png, tmp_path):
    rows = _ladder(plan, truth_png, tmp_path,
                   [synth.bend_segments(plan, d) for d in (0.0, 0.2, 0.45, 0.8)])
    _falls(rows, 0)
    _falls(rows, 2)


def test_ladder_clutter(plan, truth_png, tmp_path):
    rows = _ladder(plan, truth_png, tmp_path,
                   [synth.clutter(plan, n, seed=5, size=0.8) for n in (0, 8, 20, 40)])
    _falls(rows, 1)
    _falls(rows, 2)


def test_ladder_position_noise(plan, truth_png, tmp_path):
    rows = _ladder(plan, truth_png, tmp_path,
                   [synth.wall_points(plan, 0.05, noise=s, seed=4)
                    for s in (0.0, 0.1, 0.15, 0.2)])
    _falls(rows, 1)
    _falls(rows, 2)


def _distance_to_segments(xy: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Distance (metres) from each point (N, 2) to the nearest of the segments (M, 4)."""
    a, b = segments[None, :, :2], segments[None, :, 2:]
    ab = b - a
    t = np.clip(np.sum((xy[:, None] - a) * ab, axis=2) / np.sum(ab * ab, axis=2), 0, 1)
    return np.linalg.norm(xy[:, None] - (a + t[..., None] * ab), axis=2).min(axis=1)


def test_moved_wall_shows_its_displacement(plan, truth_png, tmp_path):
    """The L-shaped wall (walls 20 and 21) moved 0.5 m east: features next to it are displaced
    by 0.5 m, features elsewhere by under 0.1 m. A Hough segment only sees the motion across
    it: the L's east-west arm slides along itself and must show no displacement."""
    wall = plan[[20, 21]]
    moved = synth.move_wall(synth.move_wall(plan, 20, (0.5, 0.0)), 21, (0.5, 0.0))
    path = write_image_map(moved, tmp_path / "moved.png")
    result = evaluate(path, truth_png, Settings(matching=MatchingConfig(threshold=1.0),
                                                alignment=AlignmentConfig(force=True)))
    near_count = 0
    for name, det in result.detectors.items():
        if name == "rooms":  # a room's centroid moves by a share of it: tests/e2e/test_rooms.py
            continue
        gap = _distance_to_segments(det.truth_xy, wall)
        d, near, far = det.distances, gap < 0.4, gap > 2.0
        expected = np.full(len(d), 0.5)
        if name == "hough":  # segments parallel to the motion see none of it
            seg = det.truth.segments[det.matching.truth_idx]
            along = np.abs(seg[:, 2] - seg[:, 0]) > np.abs(seg[:, 3] - seg[:, 1])
            expected[along] = 0.0
        assert np.all(np.abs(d[near] - expected[near]) < 0.1), (name, d[near])
        assert np.all(d[far] < 0.1), (name, np.sort(d[far])[-5:])
        near_count += near.sum()
    assert near_count >= 4


def test_map_of_unknown_scale(plan, truth_png, tmp_path):
    """A picture of the plan at another scale, with no resolution: --map-resolution auto starts
    from the truth's 0.05 m per pixel and finds the true 0.1 m (scale 2 against that guess)."""
    import cv2

    tf = Similarity2D(-2.0, 5.0, np.radians(-70.0), 2.0)
    segments = synth.transform_segments(plan, tf.inverse())
    grid = synth.plan_grid(segments, 0.05)
    path = tmp_path / "picture.png"  # no YAML beside it
    cv2.imwrite(str(path), synth.render(segments, grid, thickness=0.075))
    result = evaluate(path, truth_png, Settings(alignment=AlignmentConfig(scale=True)))
    got = result.transform
    # the picture's frame has its origin at the image's lower-left corner, in guessed metres
    want = tf.compose(Similarity2D(grid.origin[0], grid.origin[1]))
    assert abs(got.scale - 2.0) < 0.02, got
    assert abs((got.yaw_deg - want.yaw_deg + 180) % 360 - 180) < 0.5
    assert np.hypot(got.tx - want.tx, got.ty - want.ty) < 0.1
    for name, det in result.detectors.items():
        assert det.matching.quality >= 0.9, (name, det.matching.quality)
