"""Fixtures shared by every folder of tests, and each test's kind by its folder."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.unused import leave_out_unused
from testkit import synth
from testkit.files import write_image_map
from testkit.paths import SAMPLE

leave_out_unused()  # the test processes as the command's: Open3D without IPython


@pytest.fixture(autouse=True)
def _figures_closed():
    """Figures a test opened and kept (to look at their artists) are closed after it, so that
    they do not pile up in the test process."""
    yield
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


@pytest.fixture(scope="session")
def plan() -> np.ndarray:
    return synth.building_plan(seed=0)


@pytest.fixture(scope="session")
def truth_png(plan, tmp_path_factory) -> Path:
    return write_image_map(plan, tmp_path_factory.mktemp("truth") / "truth.png")


@pytest.fixture(scope="session")
def sample_result():
    """The shipped sample evaluated with the defaults (a Result), made once for every test
    that reads it and must not change it."""
    from pcmapq.evaluation.pipeline import evaluate

    return evaluate(SAMPLE / "scan.ply", SAMPLE / "truth.png")


@pytest.fixture(scope="module")
def scan_points() -> np.ndarray:
    """The sample scan's points (N, 3), metres, in its own frame."""
    import open3d as o3d

    return np.asarray(o3d.io.read_point_cloud(str(SAMPLE / "scan.ply")).points)


TESTS = Path(__file__).resolve().parent
#: A test's kind is its folder's: tests/unit holds the fast tests of one package (``unit``:
#: ``pytest -m unit`` runs them alone), tests/realdata those that read ../shared/data
#: (``realdata``: they skip, saying why, where it is absent); the rest (tests/cli, tests/e2e,
#: tests/bench and the top level) run the command line, the whole pipeline or a subprocess
#: (``e2e``). A test marked by hand keeps that mark too: a command line stopped at its
#: parsing, in milliseconds, is marked ``unit`` and runs with ``-m unit``.
FOLDER_KINDS = {"unit": "unit", "realdata": "realdata"}


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """With ``-m unit`` alone, a test file outside tests/unit that marks no test ``unit`` by
    hand holds none to run: it is not imported (the e2e and real-data modules' imports and
    assertion rewriting would take most of the run)."""
    if config.option.markexpr != "unit" or collection_path.suffix != ".py":
        return None
    path = collection_path.resolve()
    if not path.is_relative_to(TESTS):
        return None
    parts = path.relative_to(TESTS).parts
    if len(parts) < 2 or parts[0] == "unit" or not parts[-1].startswith("test_"):
        return None
    return True if "mark.unit" not in path.read_text() else None


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark every test ``unit``, ``realdata`` or ``e2e`` by its folder (see FOLDER_KINDS)."""
    for item in items:
        parts = Path(item.path).resolve().relative_to(TESTS).parts
        kind = FOLDER_KINDS.get(parts[0], "e2e") if len(parts) > 1 else "e2e"
        if kind == "unit" and any(item.get_closest_marker(m) for m in ("e2e", "realdata")):
            raise pytest.UsageError(f"{item.nodeid}: tests/unit holds fast tests of one "
                                    "package only; a slower one goes to tests/e2e")
        item.add_marker(getattr(pytest.mark, kind))


@pytest.fixture(scope="module")
def campus():
    """A campus of 6 x 8 copies of the plan (164 m x 156 m, only its outline tells one copy
    from the next), and its map: turned -12 degrees and moved, 3 cm noise
    (:func:`testkit.synth.placed_campus`)."""
    return synth.placed_campus(6, 8)
