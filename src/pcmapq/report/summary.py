"""Many results side by side: one flat row per map (from a saved result JSON, or a failed run),
written as ``table.csv``, ``table.md`` and ``figure.png`` (the qualities grouped per map, like
the paper's Figure 7). Metres and degrees; an undefined figure stays None: an empty CSV cell,
'n/a' or '-' in the markdown, a gap marked 'n/a' in the figure, never a zero."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from pcmapq.core.errors import InputError
from pcmapq.io.writers import OutputSet, one_line, write_atomic
from pcmapq.results.figures import HEADERS, SCORES, TAIL, columns, ranked
from pcmapq.results.result import DECIMALS
from pcmapq.settings import DEFAULT_DETECTORS, DETECTOR_NAMES

#: Decimals of the markdown table: scale 4, degrees 2, everything else 3 (as the terminal).
MD_DECIMALS = {"scale": 4, "yaw_deg": 2}
#: Bar colours of the detectors in the figure.
COLOURS = {"harris": "#4477aa", "hough": "#ee6677", "sift": "#228833"}


def table_csv(rows: Sequence[dict[str, object]]) -> str:
    """The rows as CSV, one per map in the order given with its rank
    (:func:`~pcmapq.results.figures.ranked`), :func:`columns` order: floats with
    :data:`~pcmapq.results.result.DECIMALS` decimals, an empty cell for None."""
    import csv
    import io

    rows = ranked(list(rows))
    cols = columns(rows)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(cols)
    writer.writerows([_csv_cell(row.get(c)) for c in cols] for row in rows)
    return out.getvalue()


def table_md(rows: Sequence[dict[str, object]]) -> str:
    """The rows as a markdown table (units in the headers): scores 'n/a' when undefined,
    other figures '-' when there is none, blank in a failed row, whose status says its exit
    code and error; each row's rank (:func:`~pcmapq.results.figures.ranked`) beside its
    name."""
    rows = ranked(list(rows))
    cols = [c for c in columns(rows) if c not in TAIL]
    headers = [_header(c) for c in cols] + ["status"]
    lines = ["| " + " | ".join(headers) + " |",
             "|" + "|".join("---" if c in ("name", "map", "truth") else "---:"
                            for c in cols) + "|---|"]
    for row in rows:
        failed = bool(row.get("exit_code"))
        cells = [_md_cell(c, row.get(c), failed) for c in cols]
        status = f"failed (exit {row['exit_code']}): {row.get('error', '')}" if failed else "ok"
        lines.append("| " + " | ".join([*cells, _escape(status)]) + " |")
    return "\n".join(lines) + "\n"


def shown_detectors(rows: Sequence[dict[str, object]]) -> list[str]:
    """The detectors a summary shows: those run by default, and any other some row has."""
    return [d for d in DETECTOR_NAMES if d in DEFAULT_DETECTORS
            or any(row.get(f"{d}_quality") is not None for row in rows)]


def terminal_columns(rows: Sequence[dict[str, object]]) -> dict[str, str]:
    """The columns of the terminal's table and their short headers: the comparison at a
    glance (the files hold every column)."""
    return {**{f"{d}_quality": d for d in shown_detectors(rows)}, "coverage": "coverage",
            "accuracy_mean_m": "accuracy\n(m)", "completeness_mean_m": "completeness\n(m)"}


def print_summary(rows: Sequence[dict[str, object]], console) -> None:
    """The rows at a glance on a rich ``console``: name, each detector's quality, coverage,
    the mean wall distances (metres) and 'ok' or the exit code, cells as in the markdown
    table; then one line per failed row with its error."""
    from rich import box
    from rich.table import Table
    from rich.text import Text

    table = Table(box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False, padding=(0, 0, 0, 1),
                  title="feature quality per detector; accuracy, completeness: mean wall "
                  "distances", title_justify="left")
    table.add_column("name", no_wrap=True)
    table.add_column("rank", justify="right", no_wrap=True)
    rows = ranked(list(rows))
    columns = terminal_columns(rows)
    for header in columns.values():
        table.add_column(header, justify="right", no_wrap=True)
    table.add_column("status", no_wrap=True)
    for row in rows:
        failed = bool(row.get("exit_code"))
        table.add_row(Text(str(row.get("name"))), str(row["rank"]),
                      *(_md_cell(c, row.get(c), failed) for c in columns),
                      f"exit {row['exit_code']}" if failed else "ok")
    console.print(table, highlight=False)
    for row in rows:
        if row.get("exit_code"):
            console.print(f"{row.get('name')}: failed (exit {row['exit_code']}): "
                          f"{row.get('error', '')}", markup=False, highlight=False,
                          soft_wrap=True)


#: The panels of the summary figure: a detector's score and its axis label.
PANELS = (("quality", "quality\n(matched truth / truth)"),
          ("precision", "precision\n(matched map / map)"),
          ("f1", "f1"))


def summary_figure(rows: Sequence[dict[str, object]]):
    """Each detector's quality, precision and f1 grouped per map, a panel each (quality is the
    paper's Figure 7): one bar per detector, a gap marked 'n/a' where a score is undefined,
    'failed (exit N)' over a failed map's group. A matplotlib Figure (Agg)."""
    from pcmapq.report.plot import plt  # matplotlib on the Agg backend

    n, k = len(rows), len(shown_detectors(rows))
    width = 0.8 / k
    fig, axes = plt.subplots(len(PANELS), 1, sharex=True, layout="constrained",
                             figsize=(min(max(4.0, 1.2 + 0.9 * n), 20.0), 2.6 * len(PANELS)))
    for ax, (score, label) in zip(axes, PANELS, strict=True):
        _score_panel(ax, rows, score, width)
        ax.set_ylabel(label)
    axes[0].set_title("feature quality, precision and f1 per map")
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    axes[-1].set_xticks(range(n), [str(row.get("name")) for row in rows],
                        rotation=30 if n > 6 else 0, ha="right" if n > 6 else "center")
    axes[-1].set_xlim(-0.6, n - 0.4)
    return fig


def _score_panel(ax, rows: Sequence[dict[str, object]], score: str, width: float) -> None:
    """One panel of :func:`summary_figure`: ``score`` of every detector, per map."""
    names = shown_detectors(rows)
    k = len(names)
    for j, det in enumerate(names):
        xs = [i + (j - (k - 1) / 2) * width for i in range(len(rows))]
        values = [row.get(f"{det}_{score}") for row in rows]
        shown = [(x, v) for x, v, row in zip(xs, values, rows, strict=True)
                 if v is not None and not row.get("exit_code")]
        ax.bar([x for x, _ in shown], [v for _, v in shown], width, color=COLOURS.get(det),
               label=det)
        for x, v, row in zip(xs, values, rows, strict=True):
            if v is None and not row.get("exit_code"):
                ax.text(x, 0.02, "n/a", rotation=90, ha="center", va="bottom", fontsize=7,
                        color="0.4")
    for i, row in enumerate(rows):
        if row.get("exit_code"):
            ax.text(i, 0.5, f"failed (exit {row['exit_code']})", rotation=90, ha="center",
                    va="center", fontsize=8, color="#aa3377")
    ax.set_ylim(0.0, 1.05)


def write_summary(rows: Sequence[dict[str, object]], out_dir: Path) -> list[Path]:
    """Write ``out_dir/table.csv``, ``table.md`` and ``figure.png`` (made if missing), all or
    none (:class:`~pcmapq.io.writers.OutputSet`); the same rows give the same bytes. The
    paths written."""
    from pcmapq.report.plot import figure_bytes

    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{out_dir}: cannot make the folder: {one_line(exc)}") from None
    with OutputSet() as outputs:
        write_atomic(out_dir / "table.csv", table_csv(rows), outputs)
        write_atomic(out_dir / "table.md", table_md(rows), outputs)
        write_atomic(out_dir / "figure.png", figure_bytes(summary_figure(rows), "png"),
                     outputs)
        return outputs.commit()


def _csv_cell(value: object) -> str:
    """A CSV cell: empty for None, DECIMALS decimals for a float (-0 as 0)."""
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value + 0.0:.{DECIMALS}f}"
    return str(value)


def _header(column: str) -> str:
    """A column's markdown header, units in brackets."""
    if column.startswith("f_score@"):
        return f"F@{column[len('f_score@'):-1]} m"
    return HEADERS[column]


def _md_cell(column: str, value: object, failed: bool) -> str:
    """A markdown cell: a score 'n/a' when undefined, another figure '-' when there is none,
    blank in a failed row."""
    if column == "rank":
        return str(value)
    if value is None:
        if failed:
            return ""
        return "n/a" if column.endswith(SCORES) else "-"
    if isinstance(value, float):
        return f"{value + 0.0:.{MD_DECIMALS.get(column, 3)}f}"
    return _escape(str(value))


def _escape(text: str) -> str:
    """Text safe in a markdown cell: one line, '|' escaped."""
    return " ".join(text.split()).replace("|", "\\|")
