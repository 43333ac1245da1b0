"""The comparison table of many results (report/summary.py, results/figures.py): a failed row has
no figures, the CSV's columns are the union of the taus in order, the gates' verdict in a word."""

from __future__ import annotations

from itertools import combinations

import numpy as np
from matplotlib.colors import to_rgb

from pcmapq.report.style import DETECTOR_COLOURS
from pcmapq.report.summary import summary_figure, table_csv
from pcmapq.results.rows import columns, failed_row, head
from pcmapq.settings import DETECTOR_NAMES


def test_failed_row_has_no_figures():
    row = failed_row("b", "m.ply", "t.yaml", 1, "m.ply: alignment failed")
    shown = [c for c in columns([row]) if c in head()]  # 3D (sparse) columns: where a row has them
    assert set(shown) <= set(row) and set(shown) < set(head())
    assert all(row[k] is None for k in shown if k not in ("name", "map", "truth"))
    assert (row["exit_code"], row["error"]) == (1, "m.ply: alignment failed")


def test_csv_columns_are_the_union_of_taus_in_order():
    a = {**failed_row("a", "a", "t", 1, "x"), "f_score@0.5m": 0.5}
    b = {**failed_row("b", "b", "t", 1, "x"), "f_score@0.05m": 0.1}
    header = table_csv([a, b]).splitlines()[0].split(",")
    assert header[:-5] == [c for c in head() if c in a]
    assert header[-5:] == ["f_score@0.05m", "f_score@0.5m", "gates", "exit_code", "error"]


def test_gates_verdict_in_a_word():
    from pcmapq.results.rows import gates_verdict
    assert gates_verdict(None) == ""
    assert gates_verdict([{"key": "coverage", "passed": True}]) == "pass"
    assert gates_verdict([{"key": "harris.quality", "passed": False},
                          {"key": "coverage", "passed": True},
                          {"key": "accuracy.mean", "passed": False}]) == \
        "fail: harris.quality, accuracy.mean"


def test_rank_puts_refused_and_failed_maps_last():
    """Scored maps by their mean f1, then a scored map without f1, then a map of another
    place (refused, or forced: by f1 too), then a map that failed otherwise; the rows keep
    their order."""
    from pcmapq.report.summary import table_md
    from pcmapq.results.rows import ranked

    def scored(name, f1, verdict="same place"):
        return {**failed_row(name, name, "t", 0, ""), "verdict": verdict, "exit_code": 0,
                "error": "", "harris_f1": f1, "sift_f1": None if f1 is None else f1 / 2}

    rows = [failed_row("broken", "broken", "t", 2, "broken: cannot be read"),
            failed_row("other", "other", "t", 1, "other: does not seem...", "another place"),
            scored("forced", 0.9, "another place"), scored("good", 0.8), scored("none", None),
            scored("better", 0.9, "placed with low confidence")]
    assert [r["rank"] for r in ranked(rows)] == [6, 5, 4, 2, 3, 1]
    md = table_md(rows).splitlines()
    assert md[0].startswith("| name | rank |") and md[2].startswith("| broken | 6 |")
    assert "another place" in md[3]


def test_every_detector_has_its_own_colour_in_the_figure():
    """One colour per detector, from one table: every detector has one, no two closer than
    100 (RGB, 0-255 a channel: harris and rooms were 38 apart), and each detector's bars in the
    compare figure have it."""
    assert set(DETECTOR_NAMES) <= set(DETECTOR_COLOURS)
    for a, b in combinations(DETECTOR_NAMES, 2):
        gap = 255 * np.linalg.norm(np.subtract(to_rgb(DETECTOR_COLOURS[a]),
                                               to_rgb(DETECTOR_COLOURS[b])))
        assert gap > 100, (a, b, gap)
    row = {**failed_row("m", "m", "t", 0, ""), "exit_code": 0,
           **{f"{d}_{s}": 0.5 for d in DETECTOR_NAMES for s in ("quality", "precision", "f1")}}
    bars = {c.get_label(): c.patches[0].get_facecolor()[:3]
            for c in summary_figure([row]).axes[0].containers}
    assert set(bars) == set(DETECTOR_NAMES)
    for name, rgb in bars.items():
        np.testing.assert_allclose(rgb, to_rgb(DETECTOR_COLOURS[name]), atol=1e-6)
