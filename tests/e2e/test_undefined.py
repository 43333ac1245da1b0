"""Undefined is not zero: a detector with nothing to count reports null / n/a and why."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from rich.console import Console
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.html import report_html
from pcmapq.report.plot import vectorial_figure
from pcmapq.report.table import print_table
from pcmapq.settings import AlignmentConfig, FootprintConfig, MatchingConfig, Settings
from testkit.files import write_image_map


def polygon(corners: np.ndarray) -> np.ndarray:
    """The closed polygon through ``corners`` (N, 2) metres as N wall segments (N, 4)."""
    return np.hstack([corners, np.roll(corners, -1, axis=0)])


def round_room(radius: float = 5.0, sides: int = 90) -> np.ndarray:
    """A round room: a circle of walls, no corner anywhere (sides of 0.35 m, 4 deg turns)."""
    a = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
    return polygon(np.column_stack([radius * np.cos(a), radius * np.sin(a)]))


def rounded_square(half: float = 4.0, radius: float = 1.5, steps: int = 12) -> np.ndarray:
    """A square room 2 * half metres wide whose corners are quarter circles of ``radius``."""
    c = half - radius
    arcs = [np.column_stack([sx * c + radius * np.cos(a), sy * c + radius * np.sin(a)])
            for k, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1)))
            for a in [np.linspace(k * np.pi / 2, (k + 1) * np.pi / 2, steps)]]
    return polygon(np.vstack(arcs))


@pytest.fixture(scope="module")
def round_png(tmp_path_factory):
    return write_image_map(round_room(), tmp_path_factory.mktemp("round") / "round.png")


@pytest.fixture(scope="module")
def round_result(round_png):
    """A perfect map of a round room scored against itself."""
    return evaluate(round_png, round_png)


def test_round_room_has_no_corner_to_score(round_result):
    harris, hough, sift = (round_result.detectors[n].matching for n in ("harris", "hough", "sift"))
    for m in (harris, sift):  # nothing to count on either side: undefined, not 0
        assert m.truth_features == 0 and m.map_features == 0
        assert (m.quality, m.precision, m.f1) == (None, None, None)
    assert round_result.note("harris") == ("no strong truth feature inside the footprint; "
                                           "no strong map feature")
    # Hough sees the walls: a perfect map scores as it does
    assert hough.truth_features > 0 and hough.quality >= 0.9 and hough.f1 >= 0.9
    assert round_result.note("hough") is None


def test_round_room_json_table_report_plot(round_result):
    doc = json.loads(round_result.to_json())  # valid JSON: null, not NaN
    det = doc["detectors"]
    assert det["harris"]["quality"] is None and det["harris"]["f1"] is None
    assert det["sift"]["precision"] is None
    assert det["harris"]["note"].startswith("no strong truth feature inside the footprint")
    assert det["hough"]["note"] is None and det["hough"]["quality"] >= 0.9
    buf = io.StringIO()
    print_table(round_result, Console(file=buf, width=200))
    table = buf.getvalue()
    rows: dict[str, str] = {}  # the score table's rows, the first of each detector's
    lines = table.splitlines()
    start = next(i for i, line in enumerate(lines) if line.split()[:2] == ["detector", "quality"])
    for line in lines[start:]:
        if line.split()[:1] in (["harris"], ["hough"], ["sift"]):
            rows.setdefault(line.split()[0], line)
    assert rows["harris"].count("n/a") == 3 and rows["sift"].count("n/a") == 3
    assert "n/a" not in rows["hough"]
    assert "harris: n/a: no strong truth feature" in table
    page = report_html(round_result)
    assert "<td>n/a</td>" in page and "sift: n/a: no strong truth feature" in page
    fig = vectorial_figure(round_result)
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert sum("quality n/a" in t for t in titles) == 3, titles  # harris, sift, rooms
    assert any("the truth has 1 room, fewer than 2: nothing to find" in t for t in titles)


def test_with_full_the_note_does_not_mention_the_footprint(round_png):
    result = evaluate(round_png, round_png, Settings(footprint=FootprintConfig(full=True),
                                                     matching=MatchingConfig(detectors=("harris",))))
    assert result.note("harris") == "no strong truth feature; no strong map feature"


def test_map_without_strong_features(tmp_path):
    """A square room mapped with rounded corners: the truth has 4 corners, the map none. The
    quality is defined (0 of 4 found), the precision is not, nor f1."""
    truth = write_image_map(polygon(np.array([[-4, -4], [4, -4], [4, 4], [-4, 4]], float)),
                            tmp_path / "square.png")
    mapped = write_image_map(rounded_square(), tmp_path / "rounded.png")
    settings = Settings(matching=MatchingConfig(detectors=("harris", "hough")),
                        alignment=AlignmentConfig(force=True))
    result = evaluate(mapped, truth, settings)
    harris = result.detectors["harris"].matching
    assert (harris.truth_features, harris.map_features) == (4, 0)
    assert harris.quality == 0.0 and harris.precision is None and harris.f1 is None
    assert result.note("harris") == "no strong map feature"
    hough = result.detectors["hough"].matching  # the four straight walls are there
    assert hough.quality == 1.0 and result.note("hough") is None


def test_cli_prints_na_and_writes_null(round_png, tmp_path):
    out = tmp_path / "r.json"
    res = CliRunner().invoke(app, ["eval", str(round_png), str(round_png), "--detectors",
                                   "harris,hough", "--json", str(out)])
    assert res.exit_code == 0, res.output
    assert "n/a" in res.output and "no strong truth feature" in res.output
    doc = json.loads(out.read_text())
    assert doc["detectors"]["harris"]["quality"] is None
    assert doc["detectors"]["hough"]["quality"] >= 0.9
