"""A Halmstad robot map against its building's layout, both in pixels, scale unknown: the
annotated keypoints land where the layout has them."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np

from pcmapq.align import AlignParams, align
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.evaluation.same_place import MIN_AGREEING, STANDS_OUT
from pcmapq.results.result import INCONSISTENT, SAME
from testkit import synth
from testkit.paths import SHARED_DATA, shared
from testkit.realdata import halmstad


def occupied_pixels(mask: np.ndarray) -> np.ndarray:
    """Centres (N, 2) of the true pixels, x = column, y = rows - 1 - row (origin lower-left, as
    the Halmstad annotations)."""
    v, u = np.nonzero(mask)
    return np.column_stack([u, mask.shape[0] - 1 - v]).astype(np.float64)


def test_halmstad_e5_09_against_layout():
    """A robot map of building E5 against the building's layout, both in pixels: the annotated
    map keypoints must land within 20 px (median) of their layout partners. The reference, a
    least-squares similarity on the keypoints: scale 0.829, yaw 91.2 deg, median residual 4 px."""
    root = ("halmstad", "maps", "E5")
    notes = ("halmstad", "annotations")
    robot = cv2.imread(str(shared(*root, "pseudo_occupancy", "E5_09.png")), cv2.IMREAD_GRAYSCALE)
    layout = cv2.imread(str(shared(*root, "layout", "E5_layout.png")), cv2.IMREAD_UNCHANGED)
    pairs = np.load(shared(*notes, "association_E5_09_E5_layout.npy"), allow_pickle=True)
    pairs = np.array([p for p in pairs if p[0] is not None and p[1] is not None], dtype=int)
    map_keys = np.load(shared(*notes, "keypoints_E5_09.npy")).astype(np.float64)[pairs[:, 0]]
    layout_keys = np.load(shared(*notes, "keypoints_E5_layout.npy")).astype(np.float64)
    layout_keys = layout_keys[pairs[:, 1]]
    map_xy = occupied_pixels(robot == 0)
    truth_xy = occupied_pixels(layout[..., :3].mean(axis=2) < 100)
    # Lengths in layout pixels: 1 px voxels, 4 px inlier tolerance.
    result = align(map_xy, truth_xy, AlignParams(tolerance=4.0, voxel=1.0), scale=True)
    residual = np.linalg.norm(result.transform.apply(map_keys) - layout_keys, axis=1)
    assert np.median(residual) < 20.0
    assert abs(result.transform.scale - 0.829) < 0.02 and abs(result.transform.yaw_deg - 91) < 2


def test_bent_map_keeps_its_scale(tmp_path):
    """HIH_01 bent so that its far corner moves 8 % of its diagonal fits its small, symmetric
    building as well at half its scale in one half of it (fitness 0.432 against 0.424) as at
    its own scale (1.175 unbent); the walls of the truth each pose covers (18 % against 57 %)
    tell them apart: scored as the same place, at its scale."""
    map_path, layout = (shared(*p.relative_to(SHARED_DATA).parts)
                        for p in halmstad.paths(SHARED_DATA, "HIH_01"))
    image = cv2.imread(str(map_path), cv2.IMREAD_UNCHANGED)
    drawn = tmp_path / "HIH_01_bent.png"
    cv2.imwrite(str(drawn), synth.bend_image(image, 0.08, 127))
    result = evaluate(drawn, halmstad.halmstad_truth(layout, tmp_path), halmstad.SETTINGS)
    assert abs(result.alignment.transform.scale - 1.175) < 0.02
    assert result.overlap.verdict == SAME


def test_a_map_bent_until_half_of_it_is_off_is_scored_not_refused(tmp_path):
    """E5_07 bent so that its far corner moves 16 % of its diagonal: half the layout's walls it
    covers lie off it (recall 0.51, confidence 0.28) and only 2 of its 8 parts, an eighth of an
    office floor each, land near its pose; yet no pose elsewhere scores within 70 % of its
    own (distinctiveness 0.42): a bad map of the right place, scored, not refused."""
    map_path, layout = (shared(*p.relative_to(SHARED_DATA).parts)
                        for p in halmstad.paths(SHARED_DATA, "E5_07"))
    image = cv2.imread(str(map_path), cv2.IMREAD_UNCHANGED)
    drawn = tmp_path / "E5_07_bent.png"
    cv2.imwrite(str(drawn), synth.bend_image(image, 0.16, 127))
    settings = replace(halmstad.SETTINGS, matching=replace(halmstad.SETTINGS.matching,
                                                           detectors=()))
    result = evaluate(drawn, halmstad.halmstad_truth(layout, tmp_path), settings)
    cover = result.overlap
    assert cover.verdict == INCONSISTENT
    assert cover.confidence < 0.5 and sum(p.agrees for p in cover.parts) < MIN_AGREEING
    assert result.alignment.distinctiveness >= STANDS_OUT

