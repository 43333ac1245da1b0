"""Refusals of two 3D clouds that say what helps: the memory a run needs, with what most of it
is for and only the options that would bring it within the limit; a 3D registration that
fails, naming both files and a unit that looks wrong."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pcmapq.core import memory
from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.evaluation.placing import align_clouds_3d
from pcmapq.evaluation.truth import prepare_truth
from pcmapq.io import PointMap
from pcmapq.settings import Settings, SourceConfig


def terrain(seed: int, side: float, n: int = 20_000) -> np.ndarray:
    """An airborne-like cloud (N, 3) metres: a sloping ground ``side`` metres wide with 30
    buildings 3 to 15 m high."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, side, (n, 2))
    z = 0.01 * xy[:, 0] + rng.normal(0, 0.2, n)
    for _ in range(30):
        centre, half = rng.uniform(0.05 * side, 0.95 * side, 2), rng.uniform(5, 20, 2)
        inside = (np.abs(xy - centre) < half).all(axis=1)
        z[inside] += rng.uniform(3, 15)
    return np.column_stack([xy, z])


def refusal(settings: Settings, limit: int) -> str:
    """The one line two 500 m clouds are refused with under ``limit`` bytes."""
    cloud = terrain(0, 500.0)
    truth = PointMap(Path("b.npy"), cloud + [3.0, -2.0, 0.0], True)
    source = PointMap(Path("a.npy"), cloud, True)
    with pytest.raises(InputError) as raised:
        prepare_truth(truth, settings, limit, maps=(0,), loaded=(source,))
    return str(raised.value)


@pytest.mark.parametrize("resolution", [None, 1.0])
def test_the_memory_refusal_names_what_most_of_it_is_for_and_only_what_helps(resolution):
    """The detectors' 0.05 m working cells over the truth's 500 m square take 10 GB whatever
    --truth-resolution: it is not advised, nor --voxel-3d (no part of the estimate)."""
    settings = replace(Settings(), truth=SourceConfig(resolution=resolution))
    line = refusal(settings, 2 * 10**9)
    assert line.startswith("a.npy against b.npy: needs about ")
    assert "GB of it for the detectors' 0.05 m cells over the truth's" in line
    assert "--truth-resolution " not in line.replace("whatever --truth-resolution", "")
    assert "--voxel-3d" not in line and "(--map-crop, --truth-crop) need less" in line


def test_a_coarser_truth_resolution_is_advised_when_it_would_fit():
    """A 1 cm truth grid (80 % of the estimate) fits at 0.05 m: advised with its estimate."""
    settings = replace(Settings(), truth=SourceConfig(resolution=0.01))
    line = refusal(settings, 15 * 10**9)
    assert "GB of it for the truth's grid of" in line and "cells of 0.01 m" in line
    assert re.search(r"--truth-resolution 0.05 needs about 12\.\d GB; or inputs cropped", line)


def test_only_a_higher_limit_helps_below_the_libraries_own_memory():
    assert memory.more_memory(int(0.5e9)).startswith("a --max-memory of 0.5 GB or more runs it")


def room(seed: int, n: int = 1200) -> np.ndarray:
    """A 12 x 8 x 3 m room (floor, four walls, a box) sampled at random, (N, 3) metres."""
    rng = np.random.default_rng(seed)
    u, k = rng.uniform(0, 1, (n, 3)), n // 6
    parts = [np.column_stack([u[:2 * k, 0] * 12, u[:2 * k, 1] * 8, np.zeros(2 * k)]),
             np.column_stack([u[:k, 0] * 12, np.zeros(k), u[:k, 2] * 3]),
             np.column_stack([np.zeros(k), u[:k, 1] * 8, u[:k, 2] * 3]),
             np.column_stack([u[:k, 0] * 12, np.full(k, 8.0), u[:k, 2] * 3]),
             np.column_stack([np.full(k, 12.0), u[:k, 1] * 8, u[:k, 2] * 3]),
             np.column_stack([4 + u[:k, 0] * 1.5, 3 + u[:k, 1], u[:k, 2] * 1.2])]
    return np.vstack(parts)


def test_clouds_in_millimetres_that_do_not_register_are_named_with_their_unit():
    """Two rooms in millimetres: at a 0.3 m voxel every point is a voxel of its own and no
    feature matches; the line names both files and what looks wrong (the 2D case's rule)."""
    source = PointMap(Path("a_mm.npy"), room(1) * 1000, True)
    truth = PointMap(Path("b_mm.npy"), (room(2) + [0.2, 0.1, 0.0]) * 1000, True)
    with pytest.raises(EvaluationError) as raised:
        align_clouds_3d(source, truth, Settings())
    line = str(raised.value)
    assert line.startswith("a_mm.npy against b_mm.npy: too few feature matches to register "
                           "the clouds at --voxel-3d 0.3 m; a_mm.npy: it spans 1.2e+04 x "
                           "8e+03 m: are its coordinates in millimetres or another unit?")
