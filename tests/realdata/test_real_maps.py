"""Real maps and scans from ../shared/data (skipped, saying why, where it is absent)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from skimage.morphology import skeletonize

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.features import DETECTORS, detect
from pcmapq.io import load_map
from pcmapq.io.writers import write_ros_map
from pcmapq.match import match
from pcmapq.raster.draw import OCCUPIED
from pcmapq.report.html import report_html
from pcmapq.settings import AlignmentConfig, Settings
from testkit.paths import shared

#: Freiburg building 079's SLAM map has no resolution; 0.05 m per pixel is assumed.
FR79_RES = 0.05


def _write_ros_map(image: np.ndarray, path: Path, resolution: float,
                   origin: tuple[float, float]) -> Path:
    return write_ros_map(path, image, resolution, origin)


@pytest.fixture(scope="module")
def fr79(tmp_path_factory) -> Path:
    image = cv2.imread(str(shared("floorplans", "freiburg_building79.png")), cv2.IMREAD_GRAYSCALE)
    return _write_ros_map(image, tmp_path_factory.mktemp("fr79") / "fr79.png", FR79_RES, (0, 0))


def test_real_slam_map_against_itself(fr79):
    result = evaluate(fr79, fr79)
    for name, det in result.detectors.items():
        assert det.matching.quality >= 0.98, name
        assert det.matching.precision >= 0.98, name


def test_thick_walled_layout_scores_like_its_skeleton():
    """A Halmstad layout (walls 0.3-0.5 m thick) against its own one-cell skeleton, both ways:
    the same walls drawn otherwise (Harris scored 0.53 before the detectors saw centre lines)."""
    source = load_map(shared("halmstad", "maps", "E5", "layout", "E5_layout.png"), 0.05)
    occ = source.state == OCCUPIED
    thin = skeletonize(occ)
    for name in DETECTORS:
        thick_f, thin_f = detect(name, occ, source.grid), detect(name, thin, source.grid)
        for m in (match(name, thick_f, thin_f), match(name, thin_f, thick_f)):
            assert m.quality >= 0.95 and m.precision >= 0.95, (name, m.quality, m.precision)


def test_real_slam_map_turned_and_shifted_is_recovered(fr79, tmp_path):
    """The Freiburg 079 SLAM map turned by 123 degrees and moved: a known rigid transform on a
    real map's texture (thin, broken, noisy walls)."""
    image = cv2.imread(str(fr79), cv2.IMREAD_GRAYSCALE)
    rows, cols = image.shape
    src = MetricGrid(FR79_RES, (0.0, 0.0, 0.0), (rows, cols))
    tf = Similarity2D(-3.0, 21.0, np.radians(123.0))  # src (truth) -> dst (map)
    corners = src.pixels_to_xy([[0, 0], [cols, 0], [0, rows], [cols, rows]])
    dst = MetricGrid.covering(tf.apply(corners), FR79_RES)
    # map pixel -> map metres -> truth metres -> truth pixel
    m = src.xy_to_pixel_matrix() @ tf.inverse().matrix @ dst.pixel_to_xy_matrix()
    turned = cv2.warpAffine(image, m[:2], dst.shape[::-1], flags=cv2.INTER_NEAREST |
                            cv2.WARP_INVERSE_MAP, borderValue=153)
    path = _write_ros_map(turned, tmp_path / "turned.png", FR79_RES, dst.origin[:2])
    result = evaluate(path, fr79)
    got, want = result.transform, tf.inverse()
    assert np.hypot(got.tx - want.tx, got.ty - want.ty) < 0.1, got
    assert abs((got.yaw_deg - want.yaw_deg + 180) % 360 - 180) < 0.5, got
    for name, det in result.detectors.items():
        assert det.matching.quality >= 0.9, (name, det.matching.quality)


def test_lidar_pair_aligns_to_its_known_transform():
    """registration/: two real LiDAR scans with their true transform. Both are 3D, so pcmapq
    registers them in 3D (no initial guess) and reports the whole transform."""
    source, target = shared("registration", "source.ply"), shared("registration", "target.ply")
    truth = np.loadtxt(shared("registration", "T_target_source.txt"))
    want = Similarity2D.from_matrix(truth)
    result = evaluate(source, target, Settings(alignment=AlignmentConfig(force=True)))
    got = result.transform
    assert np.hypot(got.tx - want.tx, got.ty - want.ty) < 0.05, got
    assert abs(got.yaw_deg - want.yaw_deg) < 0.5, got
    assert result.alignment.fitness > 0.8
    np.testing.assert_allclose(result.registration_3d.transform, truth, atol=0.02)
    assert result.distances_3d.accuracy.mean < 0.2
    assert "3D accuracy (map to truth)" in report_html(result)


def test_real_binary_partial_map_footprint_from_its_walls(fr79, tmp_path):
    """A binary map (walls black, the rest white, no unknown value) of a middle part of the
    Freiburg 079 SLAM map, turned by 200 degrees: its footprint is the area its walls enclose,
    so the coverage is the part's share of the walls and the rest of its rectangle does not
    count as missing (with its known cells: coverage 0.67, qualities 0.56-0.59)."""
    from pcmapq.io import load_map
    from pcmapq.raster.draw import OCCUPIED

    occupied = load_map(fr79).state == OCCUPIED
    rows, cols = occupied.shape
    c0, c1 = 150, 450  # columns of the part, 7.5 m to 22.5 m
    share = occupied[:, c0:c1].sum() / occupied.sum()
    part = np.full(occupied.shape, 255, np.uint8)
    part[:, c0:c1][occupied[:, c0:c1]] = 0
    src = MetricGrid(FR79_RES, (0.0, 0.0, 0.0), (rows, cols))
    tf = Similarity2D(2.0, 2.0, np.radians(200.0))  # src (truth) -> dst (map)
    x0, x1, top = c0 * FR79_RES, c1 * FR79_RES, rows * FR79_RES
    dst = MetricGrid.covering(tf.apply([[x0, 0], [x1, 0], [x0, top], [x1, top]]), FR79_RES)
    m = src.xy_to_pixel_matrix() @ tf.inverse().matrix @ dst.pixel_to_xy_matrix()
    turned = cv2.warpAffine(part, m[:2], dst.shape[::-1], flags=cv2.INTER_NEAREST |
                            cv2.WARP_INVERSE_MAP, borderValue=255)
    result = evaluate(_write_ros_map(turned, tmp_path / "part.png", FR79_RES, dst.origin[:2]),
                      fr79)
    assert result.footprint_rule == "walls"
    got, want = result.transform, tf.inverse()
    assert np.hypot(got.tx - want.tx, got.ty - want.ty) < 0.1, got
    assert abs(result.overlap.coverage - share) < 0.1, (result.overlap.coverage, share)
    for name, det in result.detectors.items():
        assert det.matching.quality >= 0.85, (name, det.matching.quality)
