"""Shared fixtures: synthetic maps written as real files, with known answers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.transform import Similarity2D
from pcmapq.io.writers import write_ros_map
from pcmapq.testing import synth

SHARED_DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def write_image_map(segments: np.ndarray, path: Path, resolution: float = 0.05) -> Path:
    """Render wall segments (metres) as a ROS map: ``path`` (.png) plus a YAML beside it."""
    grid = synth.plan_grid(segments, resolution)
    return write_ros_map(path, synth.render(segments, grid), resolution, grid.origin[:2])


def write_cloud_map(points: np.ndarray, path: Path) -> Path:
    """Save points (N, 2 or 3, metres) as .npy."""
    np.save(path, points)
    return path


def in_map_frame(segments: np.ndarray, tf: Similarity2D) -> np.ndarray:
    """The plan as seen in a map frame, where ``p_truth = tf(p_map)``."""
    return synth.transform_segments(segments, tf.inverse())


@pytest.fixture(scope="session")
def plan() -> np.ndarray:
    return synth.building_plan(seed=0)


@pytest.fixture(scope="session")
def truth_png(plan, tmp_path_factory) -> Path:
    return write_image_map(plan, tmp_path_factory.mktemp("truth") / "truth.png")


#: The plan of the alignment tests and its size, metres.
PLAN = synth.building_plan(0)
WIDTH, HEIGHT = 24.0, 16.0


@pytest.fixture(scope="module")
def truth() -> np.ndarray:
    """The plan's walls as points 5 cm apart, plan frame, metres."""
    return synth.wall_points(PLAN, spacing=0.05)


@pytest.fixture(scope="module")
def scan() -> np.ndarray:
    """The same walls sampled again with 1.5 cm noise, in the plan frame."""
    return synth.wall_points(PLAN, spacing=0.05, noise=0.015, seed=1)


def shared(*parts: str) -> Path:
    """A file of ../shared/data, or skip the test saying it is absent."""
    path = SHARED_DATA.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"{path} is absent (real data lives in ../shared/data)")
    return path


#: A test is ``realdata`` when it reads ../shared/data (through :func:`shared` or one of these
#: fixtures), ``e2e`` when it runs the whole pipeline, the command line or a subprocess (or uses
#: a fixture that does), ``unit`` otherwise: ``pytest -m unit`` runs the fast ones alone.
REALDATA_FIXTURES = {"fr79", "kitti_maps", "registration_pair"}
E2E_FIXTURES = {"moved_result", "perfect_result", "sample_json", "round_png", "summary_docs"}
E2E_CALLS = ("evaluate(", "score(", ".invoke(", "subprocess", "run(", "build_map", "_ladder(",
             "main(")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark every test ``realdata``, ``e2e`` or ``unit`` (see REALDATA_FIXTURES above)."""
    import inspect

    for item in items:
        source = inspect.getsource(item.function)
        fixtures = set(getattr(item, "fixturenames", ()))
        if "shared(" in source or fixtures & REALDATA_FIXTURES:
            item.add_marker(pytest.mark.realdata)
        elif any(call in source for call in E2E_CALLS) or fixtures & E2E_FIXTURES:
            item.add_marker(pytest.mark.e2e)
        elif item.get_closest_marker("e2e"):  # marked by hand: a whole search, seconds long
            continue
        else:
            item.add_marker(pytest.mark.unit)
