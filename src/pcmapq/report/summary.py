"""Many results side by side: one flat row per map (from a saved result JSON, or a failed run),
written as ``table.csv``, ``table.md`` and ``figure.png`` (the qualities grouped per map, like
the paper's Figure 7). Metres and degrees; an undefined figure stays None: an empty CSV cell,
'n/a' or '-' in the markdown, a gap marked 'n/a' in the figure, never a zero."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.io.writers import OutputSet, one_line, write_atomic
from pcmapq.report.style import DETECTOR_COLOURS
from pcmapq.results.figures import SCORES, by_name
from pcmapq.results.result import DECIMALS
from pcmapq.results.rows import TAIL, columns, header, ranked
from pcmapq.settings import DEFAULT_DETECTORS, DETECTOR_NAMES

#: Decimals of the markdown table: scale 4, degrees 2, everything else 3 (as the terminal).
MD_DECIMALS = {"scale": 4, "yaw_deg": 2}


def table_csv(rows: Sequence[dict[str, object]]) -> str:
    """The rows as CSV, one per map in the order given with its rank
    (:func:`~pcmapq.results.rows.ranked`), :func:`columns` order: floats with
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
    code and error; each row's rank (:func:`~pcmapq.results.rows.ranked`) beside its
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
    names = [*(f"{d}.quality" for d in shown_detectors(rows)), "coverage", "accuracy.mean",
             "completeness.mean"]
    table = by_name()
    return {table[n].column_name: table[n].short for n in names}


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
    for title in columns.values():
        table.add_column(title, justify="right", no_wrap=True)
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
    axes[-1].set_xlim(-0.6, n - 0.4)
    # laid out before the gaps' marks, which stand inside the panels: a layout measures them
    _name_labels(fig, axes[-1], [str(row.get("name")) for row in rows])
    for ax, (score, _) in zip(axes, PANELS, strict=True):
        _gap_marks(ax, rows, score, width)
    return fig


#: Most lines a map's name is wrapped onto under its bars; the characters it breaks after.
NAME_LINES, NAME_BREAKS = 4, "_-./ "


def wrapped(name: str, width: int) -> list[str]:
    """``name`` cut after its NAME_BREAKS characters into lines of at most ``width``
    characters, each as long as it can be; a piece longer than ``width`` stays whole."""
    pieces = re.findall(rf"[^{re.escape(NAME_BREAKS)}]*[{re.escape(NAME_BREAKS)}]|.+$", name)
    lines: list[str] = []
    for piece in pieces:
        if lines and len(lines[-1]) + len(piece) <= width:
            lines[-1] += piece
        else:
            lines.append(piece)
    return lines or [name]


def _name_labels(fig, ax, names: list[str]) -> None:
    """The maps' names under the bars of ``ax`` (one unit apart), none over another: level
    when each fits the width of its group of bars; else wrapped at NAME_BREAKS onto at most
    NAME_LINES lines; else upright, every k-th name where even upright ones would touch."""
    renderer = fig.canvas.get_renderer()

    def slot() -> float:
        """Pixels a name has across once ``fig`` is laid out (with 5 % to spare)."""
        fig.get_layout_engine().execute(fig)
        return 0.95 * ax.get_window_extent(renderer).width / np.ptp(ax.get_xlim())

    def widest() -> float:
        return max(t.get_window_extent(renderer).width for t in ax.get_xticklabels())

    ax.set_xticks(range(len(names)), names)
    across = slot()
    if widest() <= across:
        return
    level = ax.get_xticklabels()[0].get_window_extent(renderer).height  # one line's
    width = int(max(len(n) for n in names) * across / widest())
    lines = [wrapped(n, width) for n in names]
    if width > 0 and max(len(w) for w in lines) <= NAME_LINES:
        ax.set_xticks(range(len(names)), ["\n".join(w) for w in lines])
        if widest() <= across:
            return _taller(fig, ax, level)
    ax.set_xticks(range(len(names)), names, rotation=90)
    step = max(1, math.ceil(1.3 * level / slot()))
    ax.set_xticks(range(0, len(names), step), names[::step], rotation=90)
    _taller(fig, ax, level)


def _taller(fig, ax, level: float) -> None:
    """``fig`` made taller by what the tick labels of ``ax`` take below one level line of
    ``level`` pixels, so that the panels keep their height."""
    renderer = fig.canvas.get_renderer()
    high = max(t.get_window_extent(renderer).height for t in ax.get_xticklabels())
    fig.set_figheight(fig.get_figheight() + max(0.0, high - level) / fig.dpi)


def _bars(rows: Sequence[dict[str, object]], score: str, width: float):
    """Per detector shown: its name, the x of its bar in each map's group (maps one unit apart)
    and its ``score`` in each row (None: undefined)."""
    names = shown_detectors(rows)
    for j, det in enumerate(names):
        yield (det, [i + (j - (len(names) - 1) / 2) * width for i in range(len(rows))],
               [row.get(f"{det}_{score}") for row in rows])


def _score_panel(ax, rows: Sequence[dict[str, object]], score: str, width: float) -> None:
    """One panel of :func:`summary_figure`: the bars of ``score`` of every detector, per
    map."""
    for det, xs, values in _bars(rows, score, width):
        shown = [(x, v) for x, v, row in zip(xs, values, rows, strict=True)
                 if v is not None and not row.get("exit_code")]
        ax.bar([x for x, _ in shown], [v for _, v in shown], width, color=DETECTOR_COLOURS[det],
               label=det)
    ax.set_ylim(0.0, 1.05)


def _gap_marks(ax, rows: Sequence[dict[str, object]], score: str, width: float) -> None:
    """The marks of one panel of :func:`summary_figure`: 'n/a' where ``score`` is undefined,
    'failed (exit N)' over a failed map's group."""
    for _, xs, values in _bars(rows, score, width):
        for x, v, row in zip(xs, values, rows, strict=True):
            if v is None and not row.get("exit_code"):
                ax.text(x, 0.02, "n/a", rotation=90, ha="center", va="bottom", fontsize=7,
                        color="0.4")
    for i, row in enumerate(rows):
        if row.get("exit_code"):
            ax.text(i, 0.5, f"failed (exit {row['exit_code']})", rotation=90, ha="center",
                    va="center", fontsize=8, color="#aa3377")


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
    return header(column)


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
