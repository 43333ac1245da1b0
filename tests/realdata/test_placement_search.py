"""Placement on the real plans of ../shared/data: the global search scores as well as an exhaustive
one."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.transform import Similarity2D


def exhaustive_pose(map_xy: np.ndarray, truth_xy: np.ndarray, resolution: float) -> Similarity2D:
    """The best pose of the search's score found the slow way: every whole degree, every cell,
    the map's cells correlated with the truth's likelihood field by FFT (SciPy), not by the
    search's OpenCV template matching."""
    from scipy.signal import fftconvolve

    from pcmapq.align.coarse import likelihood_field
    from pcmapq.core.grid import MetricGrid
    from pcmapq.raster.draw import hit_counts

    centre = map_xy.mean(axis=0)
    centred = map_xy - centre
    half = int(np.ceil(np.sqrt((centred**2).sum(axis=1).max()) / resolution)) + 1
    corner = -(half + 0.5) * resolution
    cells = MetricGrid(resolution, (corner, corner, 0.0), (2 * half + 1, 2 * half + 1))
    grid = MetricGrid.covering(truth_xy, resolution, margin=(half + 1) * resolution + 2.0)
    field = likelihood_field(truth_xy, grid, resolution).astype(np.float64)
    best, pose = -1.0, Similarity2D()
    for degrees in range(360):
        turn = Similarity2D(0.0, 0.0, np.radians(degrees))
        template = (hit_counts(turn.apply(centred), cells) > 0).astype(np.float64)
        response = fftconvolve(field, template[::-1, ::-1], mode="valid") / template.sum()
        v, u = np.unravel_index(np.argmax(response), response.shape)
        if response[v, u] > best:
            at = grid.pixels_to_xy(np.array([[u + half, v + half]]))[0]
            best, pose = response[v, u], Similarity2D(*(at - turn.apply(centre[None])[0]),
                                                      turn.yaw)
    return pose


def _plan_xy(path: Path) -> np.ndarray:
    from pcmapq.core.voxels import voxel_centroids
    from pcmapq.evaluation.inputs import TRUTH_CROP, load_input, plan_points
    from pcmapq.settings import Settings, SourceConfig

    # The room-segmentation benchmark's images have no YAML: 0.05 m a pixel (its README).
    config = SourceConfig(resolution=0.05) if path.suffix == ".png" else Settings().truth
    return voxel_centroids(plan_points(load_input(path, config, TRUTH_CROP),
                                       Settings())[0], 0.05)


@pytest.mark.parametrize("pair", [("plans/bonn_youbot_tmcl/GMap/GMap.yaml",
                                   "plans/bonn_youbot_tmcl/Faro/FMap.yaml"),
                                  ("plans/bonn_youbot_tmcl/2021_10_27/YouBotMap.yaml",
                                   "plans/bonn_youbot_tmcl/Faro/FMap.yaml"),
                                  ("plans/strands_g4s/g4s_y2.yaml",
                                   "plans/strands_g4s/g4s_sim_cropped.yaml"),
                                  ("rooms/Freiburg52_scan_furnitures.png",
                                   "rooms/Freiburg52_scan.png"),
                                  ("rooms/lab_ipa_furnitures.png", "rooms/lab_ipa.png"),
                                  ("rooms/office_e_furnitures.png", "rooms/office_e.png")],
                         ids=lambda pair: Path(pair[0]).stem)
def test_the_search_scores_as_well_as_an_exhaustive_one(pair):
    """Real robot maps (furniture, clutter, part of the floor) against their reference maps,
    and furnished plans of the room-segmentation benchmark against their plain plans: the
    exhaustive search's best pose (every degree, every cell) lies within 0.5 m and 2 degrees
    of the pose the global search and ICP find, and ICP from it reaches no better fitness
    (within 0.005)."""
    from pcmapq.align import align
    from pcmapq.align.coarse import auto_resolution
    from testkit.paths import shared

    map_xy, truth_xy = (_plan_xy(shared(*p.split("/"))) for p in pair)
    found = align(map_xy, truth_xy)
    best = exhaustive_pose(map_xy, truth_xy, auto_resolution(map_xy))
    turn = abs((best.yaw_deg - found.transform.yaw_deg + 180.0) % 360.0 - 180.0)
    centre = map_xy.mean(axis=0, keepdims=True)
    assert np.hypot(*(best.apply(centre) - found.transform.apply(centre))[0]) < 0.5
    assert turn < 2.0
    slow = align(map_xy, truth_xy, init=best)
    assert found.fitness >= slow.fitness - 0.005, (found, slow)
