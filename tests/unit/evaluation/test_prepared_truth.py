"""The truth prepared once for any map: what it starts on its background thread."""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pcmapq.evaluation.scoring import structures_3d
from pcmapq.evaluation.truth import plane_params, prepare_truth
from pcmapq.features.planes3d import find_planes
from pcmapq.io import PointMap
from pcmapq.settings import AlignmentConfig, Settings, StructuresConfig
from testkit import building3d


@pytest.mark.parametrize(("change", "map_3d", "found"), [
    ({}, True, True),
    ({"structures": StructuresConfig(enabled=False)}, True, False),
    ({"alignment": AlignmentConfig(enabled=False)}, True, False),
    ({}, False, False),
])
def test_a_3d_truths_planes_are_found_beside_the_registration_only_when_wanted(
        change, map_3d, found):
    """The truth's planes start on the background thread only where a 3D map will be
    registered and its structures found; they are the planes scoring would find."""
    cloud = building3d.cloud(building3d.faces(), seed=1)
    truth = PointMap(Path("b.npy"), cloud, True)
    source = PointMap(Path("a.npy"), cloud if map_3d else cloud[:, :2].copy(), map_3d)
    settings = replace(Settings(), **change)
    prepared = prepare_truth(truth, settings, maps=(0,), loaded=(source,), background=True)
    assert prepared.features  # the thread's first job
    assert (prepared.planes is not None) == found
    if found:
        again = find_planes(cloud, plane_params(settings.structures))
        assert len(again.normal) > 10
        np.testing.assert_array_equal(prepared.planes.result().normal, again.normal)


def test_truth_planes_not_yet_started_are_found_by_scoring_not_waited_for():
    """Scoring reached before the truth's thread starts its planes (still on the truth's
    features) cancels that job and finds the planes beside the map's: the same structures as
    with the planes found beforehand, and no wait for a job that would start later."""
    truth = building3d.cloud(building3d.faces(), seed=1)
    moved = building3d.moved_map()
    option = StructuresConfig()
    done: Future = Future()
    done.set_result(find_planes(truth, plane_params(option)))
    pending: Future = Future()  # never started: waiting for it would never end
    pool = ThreadPoolExecutor(1)
    job = pool.submit(structures_3d, truth, moved, option, None, pending)
    try:
        late = job.result(timeout=60)
    finally:
        if not pending.done():  # the job is waiting for it: let it end
            pending.set_result(done.result())
        pool.shutdown()
    assert pending.cancelled()
    building3d.assert_same_matches(late, structures_3d(truth, moved, option, None, done))


def test_a_truth_prepared_for_many_maps_finds_its_planes_once(monkeypatch):
    """Prepared for several maps (``pcmapq track``'s steps), a 3D cloud truth's planes are
    found once, when the first score asks, by one of the threads that ask at once; every
    score then gets the same structures as with the planes found beside it."""
    import pcmapq.evaluation.truth as truth_module

    cloud = building3d.cloud(building3d.faces(), seed=1)
    moved = building3d.moved_map()
    settings = Settings()
    calls = []

    def counted(points, params):
        calls.append(len(points))
        return find_planes(points, params)

    monkeypatch.setattr(truth_module, "find_planes", counted)
    prepared = prepare_truth(PointMap(Path("b.npy"), cloud, True), settings)
    assert calls == []  # none asked yet: a 2D run's steps never pay for them
    with ThreadPoolExecutor(3) as pool:
        scored = list(pool.map(lambda _: structures_3d(cloud, moved, settings.structures,
                                                       None, prepared.planes), range(3)))
    assert calls == [len(cloud)]
    for each in scored:
        building3d.assert_same_matches(each, structures_3d(cloud, moved, settings.structures))
