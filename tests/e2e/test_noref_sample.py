"""The no-reference figures over a random sample of a cloud's points (``eval``'s default): the
sampled points' sums are their full pass's, the means fall within their stated standard errors
of the whole cloud's, and MOM's planes come from the cloud at a third of the radius."""

from __future__ import annotations

import threading
import time

import numpy as np

from pcmapq.evaluation import noref_figures as early_figures
from pcmapq.evaluation.noref_figures import EarlyFigures, input_figures, reduced
from pcmapq.io import PointMap
from pcmapq.metrics import noref
from pcmapq.metrics.ballsums import ball_sums
from pcmapq.metrics.inspection import SAMPLED_MOM_VOXEL, noref_figures
from pcmapq.settings import Settings


def _box_room(seed: int, points: int = 60_000, growing: float = 0.01) -> np.ndarray:
    """Floor and four walls of a 6 x 4 x 2.5 m room, noise of 2 mm growing by ``growing``
    metres along x (so the per-point figures vary over the cloud), metres."""
    rng = np.random.default_rng(seed)
    size = np.array([6.0, 4.0, 2.5])
    p = rng.uniform(0, 1, (points, 3)) * size
    face = rng.integers(0, 5, points)
    p[face == 0, 2] = 0.0
    p[face == 1, 0], p[face == 2, 0] = 0.0, size[0]
    p[face == 3, 1], p[face == 4, 1] = 0.0, size[1]
    return p + rng.normal(0, 1, p.shape) * (0.002 + growing * p[:, :1] / size[0])


def test_a_sampled_points_sums_are_those_of_the_full_pass_bit_for_bit():
    points = _box_room(1, 20_000)
    full = np.empty((len(points), 10))
    for idx, sums in ball_sums(points, 0.3):
        full[idx] = sums
    queries = noref.sample_of(len(points), 1_000)
    got = list(ball_sums(points, 0.3, chunk_points=300, queries=queries))
    idx = np.concatenate([i for i, _ in got])
    assert sorted(idx) == list(queries)
    assert np.array_equal(np.concatenate([s for _, s in got]), full[idx])


def test_sampled_means_fall_within_three_standard_errors_of_the_whole_clouds():
    for seed in (2, 3, 4):
        points = _box_room(seed)
        whole = noref.scores(points, 0.3, 5)
        part = noref.scores(points, 0.3, 5, sample=3_000)
        assert part.sampled_points == 3_000 and whole.sampled_points is None
        assert 0 < part.mme_se < 0.1 and 0 < part.mpv_se < whole.mpv
        assert abs(part.mme - whole.mme) < 3 * part.mme_se
        assert abs(part.mpv - whole.mpv) < 3 * part.mpv_se
        again = noref.scores(points, 0.3, 5, sample=3_000)
        assert (again.mme, again.mpv) == (part.mme, part.mpv)  # the same draw every run


def test_a_sample_as_large_as_the_cloud_is_the_whole_cloud():
    points = _box_room(5, 5_000)
    assert noref.scores(points, 0.3, 5, sample=5_000) == noref.scores(points, 0.3, 5)


def test_sampled_mom_finds_the_rooms_planes_at_a_third_of_the_radius():
    points = _box_room(6, 30_000, growing=0.0)
    whole = noref_figures(points, 0.3, max_ward=2_000)
    part = noref_figures(points, 0.3, max_ward=2_000, sample=5_000)
    assert part["orth_voxel_m"] == 0.3 * SAMPLED_MOM_VOXEL and whole["orth_voxel_m"] is None
    assert whole["mom"] is not None and part["mom"] is not None
    assert abs(part["mom"] - whole["mom"]) < 0.1 * whole["mom"]
    assert abs(part["mom"] - 3 * 0.002**2) < 0.2 * 3 * 0.002**2  # three planes of 2 mm noise


def test_a_cloud_is_reduced_in_chunks_as_at_once():
    points = _box_room(7, 30_000).astype(np.float32)
    from pcmapq.core.voxels import voxel_centroids
    assert np.allclose(reduced(points, 0.05, 2.0), voxel_centroids(points * 2.0, 0.05),
                       rtol=0, atol=1e-12)


def test_figures_found_while_the_map_is_placed_equal_those_found_after(tmp_path):
    cloud = PointMap(tmp_path / "room.ply", _box_room(8, 20_000), True)
    flat = PointMap(tmp_path / "plan.ply",
                    np.column_stack([_box_room(9, 20_000)[:, :2], np.zeros(20_000)]), False)
    settings = Settings()
    early = EarlyFigures({"map": cloud, "truth": flat}, settings)
    assert early.get("truth") is None  # a 2D cloud's figures are left to the caller
    assert early.get("map") == input_figures(cloud, settings.noref)


def test_a_large_cloud_s_figures_wait_for_its_walls(tmp_path, monkeypatch):
    """Above DEFER_FROM points the map's figures start once its plan points are found (its wall
    band is over), and are those found at once; a cancelled evaluation's thread does no work."""
    monkeypatch.setattr(early_figures, "DEFER_FROM", 10_000)
    cloud = PointMap(tmp_path / "room.ply", _box_room(8, 20_000), True)
    settings = Settings()
    early = EarlyFigures({"map": cloud}, settings)
    time.sleep(0.2)
    assert early._thread.is_alive() and not early._figures  # waiting, nothing done
    early.walls_found()
    assert early.get("map") == input_figures(cloud, settings.noref)
    stopped = EarlyFigures({"map": cloud}, settings)
    stopped.cancel()
    stopped._thread.join(timeout=60)
    assert not stopped._thread.is_alive() and not stopped._figures


def test_the_sides_the_thread_has_not_started_are_found_by_the_caller(tmp_path, monkeypatch):
    """Scoring, free before the figures' thread has started a side, finds that side itself
    (:meth:`EarlyFigures.help`): each side found once, the figures those found at once."""
    held = threading.Event()
    monkeypatch.setattr(early_figures, "lower_priority", held.wait)  # the thread waits here
    calls: list[str] = []
    found = early_figures.input_figures

    def counted(source, config):
        calls.append(threading.current_thread().name)
        return found(source, config)

    monkeypatch.setattr(early_figures, "input_figures", counted)
    sides = {"map": PointMap(tmp_path / "a.ply", _box_room(8, 20_000), True),
             "truth": PointMap(tmp_path / "b.ply", _box_room(9, 20_000), True)}
    settings = Settings()
    early = EarlyFigures(sides, settings)
    early.help()
    assert calls == [threading.current_thread().name] * 2  # both here, the thread still held
    held.set()
    for side, cloud in sides.items():
        assert early.get(side) == found(cloud, settings.noref)
    assert len(calls) == 2  # the thread, released, found nothing left to do


def test_a_small_cloud_s_figures_start_at_once(tmp_path):
    cloud = PointMap(tmp_path / "room.ply", _box_room(8, 20_000), True)
    early = EarlyFigures({"map": cloud}, Settings())
    early._thread.join(timeout=60)
    assert set(early._figures) == {"map"}
