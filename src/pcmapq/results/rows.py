"""The flat rows of the batch, compare and track tables: a result's figures
(:mod:`pcmapq.results.figures`) under their columns, the inputs before them, the F-scores and
the outcome after; a failed evaluation's row; the rows ranked. Metres and degrees; an undefined
figure is None."""

from __future__ import annotations

import numpy as np

from pcmapq.results import figures as table  # its FIGURES read when called (figures.by_name)
from pcmapq.results.figures import (
    AT_TAU,
    AT_TAU_COLUMN,
    MEAN_PRECISION,
    NOT_IN_PRECISION,
    figures,
    value_at,
)

#: The F-score at one tau: its figure's name and its column.
F_SCORE = AT_TAU.replace("{name}", "f_score")
F_SCORE_COLUMN = AT_TAU_COLUMN.replace("{name}", "f_score")
#: The columns before the figures: the name, its rank among the table's rows (:func:`ranked`)
#: and the inputs.
INPUTS = ("name", "rank", "map", "truth")
#: Columns after the F-scores: the gates' verdict ("" without gates, "pass", or "fail: " and
#: the failing keys) and how the evaluation ended (0 and "" when it finished).
TAIL = ("gates", "exit_code", "error")
#: Markdown headers of the columns that are not figures.
OTHER_HEADERS = {"name": "name", "rank": "rank", "map": "map", "truth": "truth",
                 "gates": "gates", "exit_code": "exit code", "error": "error"}


def head() -> tuple[str, ...]:
    """Columns before the F-scores: :data:`INPUTS`, then every figure that has a column."""
    return (*INPUTS, *(f.column_name for f in table.FIGURES if f.column))


def header(column: str) -> str:
    """A column's markdown header (units in brackets); an F-score's is its column."""
    figure = next((f for f in table.FIGURES if f.column and f.column_name == column), None)
    return figure.header if figure else OTHER_HEADERS.get(column, column)


def step_columns(doc: dict, precisions: dict[str, float | None]) -> dict[str, float | None]:
    """The columns a step of ``pcmapq track`` adds to :func:`table_row`'s: the detectors'
    mean precision (:data:`MEAN_PRECISION`, of ``precisions`` by detector, unrounded) and the
    wall precision at each tau (``wall_precision@0.1m``)."""
    values = figures(doc)
    kept = [p for d, p in precisions.items() if p is not None and d not in NOT_IN_PRECISION]
    columns: dict[str, float | None] = {
        MEAN_PRECISION: float(np.mean(kept)) if kept else None}
    for f in value_at(doc, "distances", "f_score"):
        name = AT_TAU.format(name="wall_precision", dim="", tau=f["tau_m"])
        columns[AT_TAU_COLUMN.format(name="wall_precision", tau=f["tau_m"])] = values[name]
    return columns


def table_row(name: str, doc: dict) -> dict[str, object]:
    """One flat row of a result JSON document (``pcmapq eval --json``): the inputs' paths,
    every figure that has a column (:func:`head`), the F-score at each tau and the verdict of
    its gates (:func:`gates_verdict`); exit_code 0, error ""; its rank None until the table's
    rows are ranked (:func:`ranked`). ValueError as :func:`figures`."""
    values = figures(doc)
    row: dict[str, object] = {"name": name, "rank": None, "map": value_at(doc, "map", "path"),
                              "truth": value_at(doc, "truth", "path")}
    row.update((f.column_name, values[f.name]) for f in table.FIGURES
               if f.column and not (f.sparse and values[f.name] is None))
    for f in value_at(doc, "distances", "f_score"):
        tau = f["tau_m"]
        row[F_SCORE_COLUMN.format(tau=tau)] = values[F_SCORE.format(dim="", tau=tau)]
    return {**row, "gates": gates_verdict(doc.get("gates")), "exit_code": 0, "error": ""}


def failed_row(name: str, map_path: str, truth_path: str, exit_code: int,
               error: str, verdict: str | None = None) -> dict[str, object]:
    """The row of an evaluation that failed: its inputs, exit code and one-line error, every
    figure None but the ``verdict`` of a map refused as another place."""
    row: dict[str, object] = dict.fromkeys(c for c in head() if c not in _sparse())
    return {**row, "name": name, "map": str(map_path), "truth": str(truth_path),
            "verdict": verdict, "gates": "", "exit_code": int(exit_code),
            "error": " ".join(str(error).split())}


def ranked(rows: list[dict[str, object]]) -> list[dict[str, object]]:
    """The rows, in their order, each with its ``rank`` (1 the best): maps scored as showing
    the truth's place first, by the mean f1 of their detectors (those defined), highest first;
    then scored maps with no f1; then maps of another place (refused, or scored with
    ``--force``); then rows that failed otherwise. Ties keep the rows' order."""
    def key(i: int) -> tuple[int, float, int]:
        row = rows[i]
        f1 = [v for k, v in row.items() if k.endswith("_f1") and isinstance(v, float)]
        group = (3 if row.get("exit_code") and row.get("verdict") is None else
                 2 if row.get("verdict") == "another place" else 0 if f1 else 1)
        return group, -(sum(f1) / len(f1)) if f1 else 0.0, i

    order = sorted(range(len(rows)), key=key)
    rank = {i: r for r, i in enumerate(order, 1)}
    return [{**row, "rank": rank[i]} for i, row in enumerate(rows)]


def gates_verdict(gates: list[dict] | None) -> str:
    """A result's ``gates`` block (``pcmapq eval --fail-under/--fail-over``) in a word: "" when
    none, "pass", or "fail: " and the keys that failed."""
    if not gates:
        return ""
    failed = [g["key"] for g in gates if not g["passed"]]
    return "fail: " + ", ".join(failed) if failed else "pass"


def columns(rows: list[dict[str, object]]) -> list[str]:
    """A table's columns: :func:`head` (a sparse figure's only when some row has it), the
    F-score of every tau any row has (ascending), :data:`TAIL`."""
    taus = sorted({float(k[len("f_score@"):-1]) for row in rows for k in row
                   if k.startswith("f_score@")})
    sparse = _sparse()
    kept = [c for c in head()
            if c not in sparse or any(row.get(c) is not None for row in rows)]
    return [*kept, *(F_SCORE_COLUMN.format(tau=t) for t in taus), *TAIL]


def _sparse() -> set[str]:
    """The columns of :attr:`Figure.sparse` figures."""
    return {f.column_name for f in table.FIGURES if f.column and f.sparse}
