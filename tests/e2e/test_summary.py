"""The comparison table and figure of many results (report/summary.py): rows from real result
JSONs, nulls kept as nulls (empty cell, 'n/a', a gap in the figure), the maps' names never
over one another, failed rows, outputs
written whole and the same bytes every time."""

from __future__ import annotations

import csv
import io
import json

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report import summary
from pcmapq.report.summary import summary_figure, table_csv, table_md, write_summary
from pcmapq.results.figures import FIGURES
from pcmapq.results.rows import columns, failed_row, head, table_row
from pcmapq.settings import DEFAULT_DETECTORS, DETECTOR_NAMES, MatchingConfig, Settings
from testkit import synth
from testkit.files import write_image_map
from testkit.paths import SAMPLE


@pytest.fixture(scope="module")
def summary_docs(plan, truth_png, tmp_path_factory) -> dict[str, dict]:
    """Result JSON documents, as ``eval --json`` writes them: the sample; and a synthetic map
    with 30 % of its walls dropped, scored with harris and sift only (hough null)."""
    degraded = write_image_map(synth.drop_walls(plan, 0.3, seed=1),
                               tmp_path_factory.mktemp("degraded") / "degraded.png")
    return {
        "sample": json.loads(evaluate(SAMPLE / "scan.ply", SAMPLE / "truth.yaml").to_json()),
        "degraded": json.loads(evaluate(degraded, truth_png, Settings(
            matching=MatchingConfig(("harris", "sift")))).to_json()),
    }


@pytest.fixture(scope="module")
def table_rows(summary_docs) -> list[dict[str, object]]:
    return [table_row(name, doc) for name, doc in summary_docs.items()] + [
        failed_row("broken", "maps/broken.ply", "truth.yaml", 2,
                   "maps/broken.ply: not a point cloud | nor an image\n(second line)")]


def test_a_row_holds_the_documents_figures(summary_docs):
    doc = summary_docs["sample"]
    row = table_row("sample", doc)
    shown = [c for c in columns([row]) if c in head()]  # a 2D pair: no 3D (sparse) columns
    sparse = {f.column_name for f in FIGURES if f.sparse}
    assert list(row)[:len(shown)] == shown == [c for c in head() if c not in sparse]
    assert row["map"] == doc["map"]["path"] and row["truth"] == doc["truth"]["path"]
    for det in DETECTOR_NAMES:  # a detector not run is null
        for score in ("quality", "precision", "f1"):
            assert row[f"{det}_{score}"] == doc["detectors"].get(det, {}).get(score)
    a, d = doc["alignment"], doc["distances"]
    assert [row[k] for k in ("fitness", "confidence", "x_m", "y_m", "yaw_deg", "scale")] == \
        [a[k] for k in ("fitness", "confidence", "x_m", "y_m", "yaw_deg", "scale")]
    assert row["coverage"] == doc["coverage"]
    assert row["accuracy_mean_m"] == d["accuracy_m"]["mean"]
    assert row["completeness_median_m"] == d["completeness_m"]["median"]
    assert row["chamfer_m"] == d["chamfer_m"]
    assert [row[f"f_score@{f['tau_m']:g}m"] for f in d["f_score"]] == \
        [f["f"] for f in d["f_score"]]
    assert (row["exit_code"], row["error"]) == (0, "")


def test_a_detector_not_run_is_null_not_zero(summary_docs):
    row = table_row("degraded", summary_docs["degraded"])
    assert row["hough_quality"] is None and row["hough_f1"] is None
    assert 0.0 < row["harris_quality"] < 1.0  # the dropped walls cost features


def test_a_document_missing_a_figure_is_refused_by_name(summary_docs):
    doc = json.loads(json.dumps(summary_docs["sample"]))
    del doc["alignment"]["confidence"]
    with pytest.raises(ValueError, match="alignment.confidence"):
        table_row("x", doc)
    doc = json.loads(json.dumps(summary_docs["sample"]))
    doc["coverage"] = "high"
    with pytest.raises(ValueError, match="coverage"):
        table_row("x", doc)


def test_csv_has_empty_cells_for_nulls_and_the_failures_exit_code(table_rows):
    table = list(csv.DictReader(io.StringIO(table_csv(table_rows))))
    assert [r["name"] for r in table] == ["sample", "degraded", "broken"]
    sample, degraded, broken = table
    assert float(sample["harris_quality"]) == table_rows[0]["harris_quality"]
    assert degraded["hough_quality"] == "" and degraded["hough_precision"] == ""
    assert float(degraded["sift_quality"]) == table_rows[1]["sift_quality"]
    assert broken["exit_code"] == "2" and broken["harris_quality"] == ""
    assert broken["error"] == "maps/broken.ply: not a point cloud | nor an image (second line)"
    assert sample["exit_code"] == "0" and sample["error"] == ""


def test_markdown_table_shows_nulls_and_failures(table_rows):
    lines = table_md(table_rows).splitlines()
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    assert "accuracy mean (m)" in header and "yaw (deg)" in header and "F@0.05 m" in header
    cells = {line.split("|")[1].strip(): [c.strip() for c in line.strip("|").split("|")]
             for line in lines[2:]}
    assert len(lines) == 2 + len(table_rows)
    assert cells["degraded"][header.index("hough quality")] == "n/a"
    assert cells["sample"][header.index("status")] == "ok"
    assert cells["broken"][header.index("harris quality")] == ""
    assert lines[-1].endswith("| failed (exit 2): maps/broken.ply: not a point cloud \\| "
                              "nor an image (second line) |")


@pytest.mark.parametrize("panel, score", enumerate(("quality", "precision", "f1")))
def test_figure_draws_a_bar_per_defined_score_and_marks_the_gaps(table_rows, panel, score):
    """A panel per score (quality, precision, f1: a map with precision 0.82 shows it)."""
    fig = summary_figure(table_rows)
    assert len(fig.axes) == 3
    ax = fig.axes[panel]
    assert ax.get_ylabel().startswith(score)
    bars = {c.get_label(): c for c in ax.containers}
    assert list(bars) == list(DEFAULT_DETECTORS)
    for det, container in bars.items():
        expected = [r[f"{det}_{score}"] for r in table_rows
                    if r[f"{det}_{score}"] is not None and not r["exit_code"]]
        assert [p.get_height() for p in container.patches] == pytest.approx(expected)
    assert len(bars["hough"].patches) == 1  # the degraded map's and the failed one's: gaps
    texts = [t.get_text() for t in ax.texts]
    # the degraded map ran neither hough nor rooms
    assert texts.count("n/a") == 2 and texts.count("failed (exit 2)") == 1
    labels = [t.get_text() for t in fig.axes[-1].get_xticklabels()]
    assert labels == ["sample", "degraded", "broken"]


def test_outputs_are_the_same_bytes_every_time(table_rows, tmp_path):
    first = write_summary(table_rows, tmp_path / "a")
    second = write_summary(table_rows, tmp_path / "b" / "nested")
    assert [p.name for p in first] == ["table.csv", "table.md", "figure.png"]
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes()
    assert first[2].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_outputs_are_written_whole_or_not_at_all(table_rows, tmp_path, monkeypatch):
    def broken_figure(_rows):
        raise RuntimeError("no figure")

    monkeypatch.setattr(summary, "summary_figure", broken_figure)
    with pytest.raises(RuntimeError):
        write_summary(table_rows, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_an_unwritable_folder_is_an_input_error(table_rows, tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="file"):
        write_summary(table_rows, tmp_path / "file" / "out")


def test_one_name_per_figure_reaches_the_same_value_everywhere(summary_docs):
    """A figure's name gives the same value through Result.figures(), a gate and a table
    column: the JSON path, the gate key and the column come from one table."""
    from pcmapq.results import gates
    from pcmapq.results.figures import FIGURES
    from pcmapq.results.result import Result

    doc = summary_docs["sample"]
    values = Result.from_json(json.dumps(doc)).figures()
    row = table_row("sample", doc)
    for fig in FIGURES:
        if fig.name not in values:
            continue
        if fig.column:
            assert row.get(fig.column_name) == values[fig.name], fig.name
        if fig.number and values[fig.name] is not None:
            outcome, = gates.check([gates.Gate(fig.name, 0.0, gates.OVER)], doc)
            assert outcome.value == values[fig.name], fig.name
    taus = [f["tau_m"] for f in doc["distances"]["f_score"]]
    assert [values[f"f_score@{t:g}"] for t in taus] == [f["f"] for f in doc["distances"]["f_score"]]
    assert values["harris.quality"] == doc["detectors"]["harris"]["quality"]
    assert values["accuracy.mean"] == doc["distances"]["accuracy_m"]["mean"]


def test_a_detector_run_by_choice_is_shown_where_a_row_has_it(table_rows, monkeypatch):
    """A detector not run by default (rooms, as if it were not) gets a bar and a terminal
    column once a row has it, and none while no row has."""
    assert summary.shown_detectors(table_rows) == list(DEFAULT_DETECTORS)
    monkeypatch.setattr(summary, "DEFAULT_DETECTORS", ("harris", "hough", "sift"))
    without = [{k: v for k, v in row.items() if not k.startswith("rooms_")}
               for row in table_rows]
    assert "rooms" not in summary.shown_detectors(without)
    with_rooms = [dict(without[0], rooms_quality=0.5, rooms_precision=1.0, rooms_f1=0.667),
                  *without[1:]]
    assert summary.shown_detectors(with_rooms) == \
        [d for d in DETECTOR_NAMES if d in (*DEFAULT_DETECTORS, "rooms")]
    assert "rooms_quality" in summary.terminal_columns(with_rooms)
    bars = {c.get_label() for c in summary_figure(with_rooms).axes[0].containers}
    assert "rooms" in bars


def _names_apart(fig, ax, names: list[str]) -> None:
    """The names under the bars of ``ax`` lie inside ``fig`` and none overlaps another, each
    under its own bars, in order; names are left out (every k-th shown) only where even
    upright ones would touch."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    n = len(names)
    labels = [t for t in ax.get_xticklabels() if t.get_visible() and t.get_text()]
    boxes = [t.get_window_extent(renderer) for t in labels]
    for i, box in enumerate(boxes):
        assert box.x0 >= -0.5 and box.x1 <= fig.bbox.x1 + 0.5 and box.y0 >= -0.5, box
        assert not any(box.overlaps(other) for other in boxes[i + 1:]), labels[i].get_text()
    shown = [t.get_text().replace("\n", "") for t in labels]
    ticks = [int(round(t.get_position()[0])) for t in labels]
    assert shown == [names[k] for k in ticks] and ticks == sorted(ticks)
    if len(shown) < n:  # every step-th name, and the names of step - 1 would touch
        step = ticks[1] - ticks[0]
        assert np.diff(ticks).tolist() == [step] * (len(ticks) - 1)
        per_name = (boxes[1].x0 - boxes[0].x0) / step
        assert (step - 1) * per_name < 1.3 * boxes[0].width
    assert len(shown) == n or all(t.get_rotation() == 90 for t in labels)


def test_names_too_many_to_show_upright_are_thinned():
    """120 names under a 4-inch axes (3 pixels a name): every k-th, upright, apart."""
    from pcmapq.report.plot import plt
    from pcmapq.report.summary import _name_labels

    fig, ax = plt.subplots(figsize=(4.0, 3.0), layout="constrained")
    ax.set_xlim(-0.6, 119.6)
    names = [f"intel_drift_{i}pc" for i in range(120)]
    _name_labels(fig, ax, names)
    _names_apart(fig, ax, names)
    assert 10 < len([t for t in ax.get_xticklabels() if t.get_text()]) < 60


@pytest.mark.parametrize(("n", "stem", "lines"), [
    (3, "m{}", 1), (4, "run_{}_gopi5go_house_tile_cart", 0),
    (9, "run_{}_gopi5go_house_tile_cart", 4),
    (12, "a_very_long_map_name_without_breaks{}xxxxxxxxxxxxxxxx", 0)])
def test_the_maps_names_never_overlap(n, stem, lines):
    """Few maps of short names: level; more, or longer names: wrapped (here onto 4 lines)
    where that fits, else upright (``lines`` 0); never over one another."""
    names = [stem.format(i) for i in range(n)]
    rows = [{**failed_row(name, name, "t", 0, ""), "exit_code": 0, "harris_quality": 0.5}
            for name in names]
    fig = summary_figure(rows)
    _names_apart(fig, fig.axes[-1], names)
    labels = fig.axes[-1].get_xticklabels()
    assert {t.get_text().count("\n") + 1 if t.get_rotation() == 0 else 0
            for t in labels} == {lines}
