"""The table of figures is the one place a figure is named: its JSON path, gate key, table
column and headers all follow from its line, and a line added to it reaches every output."""

from __future__ import annotations

import pytest

from pcmapq.report.docs_tables import figures_table
from pcmapq.report.summary import table_csv, table_md
from pcmapq.results import figures as table
from pcmapq.results import rows
from pcmapq.results.gates import check, parse_rules, short_names
from pcmapq.track.timeline import figures_of


@pytest.mark.parametrize(("name", "column", "header"), [
    ("harris.quality", "harris_quality", "harris quality"),
    ("alignment.fitness", "fitness", "fitness"),
    ("alignment.yaw_deg", "yaw_deg", "yaw (deg)"),
    ("accuracy.mean", "accuracy_mean_m", "accuracy mean (m)"),
    ("consistency.largest_offset_m", "largest_offset_m", "largest region offset (m)"),
    ("chamfer", "chamfer_m", "Chamfer (m)"),
])
def test_a_column_and_its_header_follow_from_the_path(name, column, header):
    figure = table.by_name()[name]
    assert figure.column_name == column and figure.header == header
    assert rows.header(column) == header


def test_a_figure_added_to_the_table_reaches_every_output(monkeypatch, sample_result):
    """One line, ``harris.matched`` made a column: Result.figures, the gates, the batch and
    compare tables (CSV and markdown), a track step and the docs' table all have it."""
    added = table.Figure("harris.matched", ("detectors", "harris", "matched"), column=True)
    monkeypatch.setattr(table, "FIGURES", (*table.FIGURES, added))
    doc = sample_result.to_dict(features=False)
    matched = doc["detectors"]["harris"]["matched"]

    assert sample_result.figures()["harris.matched"] == matched
    assert "harris.matched" in short_names()
    (outcome,) = check(parse_rules(f"harris.matched={matched}", None), doc)
    assert outcome.path == "detectors.harris.matched" and outcome.passed
    row = rows.table_row("sample", doc)
    assert row["harris_matched"] == matched
    assert "harris_matched" in table_csv([row]).splitlines()[0].split(",")
    assert "| harris matched |" in table_md([row])
    assert figures_of(sample_result)["harris_matched"] == matched
    assert "| `harris.matched` | `detectors.harris.matched` | `harris_matched` |" in \
        figures_table()


def test_an_alias_reads_its_figure(sample_result):
    doc = sample_result.to_dict(features=False)
    for alias, name in table.ALIASES.items():
        if name in sample_result.figures():
            (outcome,) = check(parse_rules(None, f"{alias}=100"), doc)
            assert outcome.path == ".".join(table.by_name()[name].path)


def test_track_s_figures_are_the_table_s(sample_result):
    """The mean precision and the wall precision at each tau are named by the table: the
    wall precision is the F-score block's precision, a gate reads it by the same name."""
    doc = sample_result.to_dict(features=False)
    step = figures_of(sample_result)
    for f in doc["distances"]["f_score"]:
        name = f"wall_precision@{f['tau_m']:g}"
        assert step[f"{name}m"] == sample_result.figures()[name] == f["precision"]
        (outcome,) = check(parse_rules(f"{name}=0", None), doc)
        assert outcome.value == f["precision"]
    kept = [d.matching.precision for n, d in sample_result.detectors.items()
            if n not in table.NOT_IN_PRECISION and d.matching.precision is not None]
    assert step[table.MEAN_PRECISION] == pytest.approx(sum(kept) / len(kept))
