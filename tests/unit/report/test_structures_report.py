"""The 3D structures in the terminal table and the HTML report, beside the 2D detectors."""

from __future__ import annotations

import io
from dataclasses import replace

import pytest
from rich.console import Console

from pcmapq.match.structures import StructureMatching
from pcmapq.report import structures
from pcmapq.report.html import report_html
from pcmapq.report.table import print_table
from pcmapq.report.text import verdict
from testkit.building3d import known_structures


@pytest.fixture(scope="module")
def result(sample_result):
    return replace(sample_result, structures=known_structures())


def shown(result, width: int = 100) -> str:
    buf = io.StringIO()
    print_table(result, Console(file=buf, width=width))
    return buf.getvalue()


def test_the_terminal_table_has_a_row_per_structure_detector(result):
    text = shown(result)
    rows: dict[str, list[str]] = {}
    for line in text.splitlines():  # the first row of each: the score table's
        if line.split()[:1] in (["planes"], ["plane_lines"]):
            rows.setdefault(line.split()[0], line.split()[1:])
    planes = result.structures.detectors["planes"].matching
    # the score row (quality, precision, f1, then the counts), then the displacements' row
    assert rows["planes"][:7] == ["1.000", "1.000", "1.000", "18", "18", "18", "18"]
    assert "3D planes and plane lines within 5 deg and 0.5 m" in " ".join(text.split())
    assert "3D structure quality/precision planes 1.00/1.00" in " ".join(text.split())
    assert planes.matched == 18
    assert max(len(line) for line in text.splitlines()) <= 100


def test_the_thresholds_name_the_shortest_line_the_settings_record(result):
    """A result of two 3D clouds records the shortest line counted: the words give it; a
    result whose settings lack it (saved before it was one) says nothing of it."""
    recorded = {**(result.settings or {}), "structures": {"line_length": 1.5}}
    words = structures.thresholds(replace(result, settings=recorded))
    assert words.startswith("3D planes and plane lines within 5 deg and 0.5 m, lines from "
                            "1.5 m long (a plane's displacement"), words
    assert "lines from" not in structures.thresholds(result)


def test_a_structure_detector_with_nothing_to_find_says_why(result):
    planes = result.structures.detectors["planes"]
    none = StructureMatching(*(planes.matching.truth_idx[:0],) * 2,
                             planes.matching.displacement[:0], planes.matching.angle[:0],
                             None, None, None, 0, 0, planes.matching.missing[:0],
                             planes.matching.extra[:0], "the truth has no plane: nothing to find")
    empty = replace(result, structures=replace(result.structures, detectors={
        **result.structures.detectors, "planes": replace(planes, matching=none)}))
    text = " ".join(shown(empty).split())
    assert "planes: n/a: the truth has no plane: nothing to find" in text
    assert "planes n/a (the truth has no plane: nothing to find)" in verdict(empty)


def test_the_report_lists_them_beside_the_2d_detectors(result, monkeypatch):
    # the page's tables are read here; its figures are drawn and checked in tests/e2e
    from pcmapq.report import html

    for figure in ("vectorial_figure", "distance_heatmap"):
        monkeypatch.setattr(html, figure, lambda *args, **kwargs: None)
    monkeypatch.setattr(html, "png_bytes", lambda figure: b"")
    page = report_html(result)
    assert "<td>planes (3D)</td><td>1.000</td>" in page
    assert "<td>plane_lines (3D)</td>" in page
    assert "3D planes: 0 missing, 0 extra, 18 matched (the largest displacement first)" in page
    wall = page.index("<td>matched</td><td>10.50, 2.49, 1.39</td>")
    assert wall < page.index("<td>matched</td><td>3.08, 2.50, 0.00</td>")  # A's floor next


def test_a_2d_result_shows_no_structures(sample_result):
    assert not [line for line in shown(sample_result).splitlines()
                if line.startswith(("planes", "plane_lines")) or "3D structure" in line]
    assert structures.html_rows(sample_result, lambda stats: []) == []
    assert structures.planes_html(sample_result) == ""
