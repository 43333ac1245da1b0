"""A result's figures, each under one name: the name a CI gate takes (``harris.quality``), the
path of the figure in the result's JSON, the column of the batch, compare and track tables
(``harris_quality``, kept as the tables have always been headed) and its markdown header. Every
reader of figures (gates, tables, track, compare, :meth:`Result.figures`) goes through
:data:`FIGURES` and :func:`figures`. Metres and degrees; an undefined figure is None."""

from __future__ import annotations

import math
from dataclasses import dataclass

from pcmapq.core.stats import FIELDS as STAT_FIELDS
from pcmapq.settings import DETECTOR_NAMES

#: A detector's scores, each in [0, 1], in table order.
SCORES = ("quality", "precision", "f1")
#: The figures of ``alignment`` a gate reaches by their own JSON name.
ALIGNMENT_FIELDS = ("confidence", "fitness", "rmse_m", "truth_recall", "seen_through",
                    "agreement", "distinctiveness", "contradiction", "free_on_truth", "x_m",
                    "y_m", "yaw_deg", "scale")


@dataclass(frozen=True)
class Figure:
    """One figure: its ``name`` (gates, :meth:`Result.figures`), its ``path`` in the result's
    JSON, its table ``column`` and markdown ``header`` (None: not a table column). ``optional``:
    a result without it reads None (a detector not run, a result without a consistency map);
    otherwise a document without it is not a result. ``number``: False for a word (the
    verdict), which no gate reads."""

    name: str
    path: tuple[str, ...]
    column: str | None = None
    header: str | None = None
    optional: bool = False
    number: bool = True


def _stats(side: str, block: str, suffix: str) -> list[Figure]:
    """``accuracy.mean`` ...: every statistic of one side's distances (mean and median are
    table columns of the 2D distances)."""
    return [Figure(f"{side}{suffix}.{s}", (block, f"{side}_m", s),
                   f"{side}_{s}_m" if not suffix and s in ("mean", "median") else None,
                   f"{side} {s} (m)", optional=bool(suffix) or s not in ("mean", "median"))
            for s in STAT_FIELDS]


#: Every named figure, table columns in table order first.
FIGURES: tuple[Figure, ...] = (
    *(Figure(f"{d}.{s}", ("detectors", d, s), f"{d}_{s}", f"{d} {s}", optional=True)
      for s in SCORES for d in DETECTOR_NAMES),
    Figure("coverage", ("coverage",), "coverage", "coverage"),
    Figure("alignment.fitness", ("alignment", "fitness"), "fitness", "fitness"),
    Figure("alignment.confidence", ("alignment", "confidence"), "confidence", "confidence"),
    Figure("alignment.verdict", ("alignment", "verdict"), "verdict", "verdict", optional=True,
           number=False),
    Figure("alignment.x_m", ("alignment", "x_m"), "x_m", "x (m)"),
    Figure("alignment.y_m", ("alignment", "y_m"), "y_m", "y (m)"),
    Figure("alignment.yaw_deg", ("alignment", "yaw_deg"), "yaw_deg", "yaw (deg)"),
    Figure("alignment.scale", ("alignment", "scale"), "scale", "scale"),
    Figure("consistency.largest_offset_m", ("consistency", "largest_offset_m"),
           "largest_offset_m", "largest region offset (m)", optional=True),
    *(f for f in _stats("accuracy", "distances", "") if f.column),
    *(f for f in _stats("completeness", "distances", "") if f.column),
    Figure("chamfer", ("distances", "chamfer_m"), "chamfer_m", "Chamfer (m)"),
    *(f for f in _stats("accuracy", "distances", "") if not f.column),
    *(f for f in _stats("completeness", "distances", "") if not f.column),
    *(Figure(f"alignment.{a}", ("alignment", a), optional=True) for a in ALIGNMENT_FIELDS
      if a not in ("confidence", "fitness", "x_m", "y_m", "yaw_deg", "scale")),
    *_stats("accuracy", "distances_3d", "_3d"), *_stats("completeness", "distances_3d", "_3d"),
    Figure("chamfer_3d", ("distances_3d", "chamfer_m"), optional=True),
)
BY_NAME = {f.name: f for f in FIGURES}
#: The groups every result has (a document without one is not a result).
REQUIRED = ("map", "truth", "detectors", "alignment", "distances")
#: An F-score's name and column, one per tau of the result (``f_score@0.05``,
#: ``f_score@0.05m``); ``f_score_3d@TAU`` for two 3D clouds.
F_SCORE, F_SCORE_COLUMN = "f_score{dim}@{tau:g}", "f_score@{tau:g}m"
#: Columns before the F-scores: the name, its rank among the table's rows (:func:`ranked`)
#: and inputs, then every figure that has a column.
HEAD = ("name", "rank", "map", "truth", *(f.column for f in FIGURES if f.column))
#: Columns after the F-scores: the gates' verdict ("" without gates, "pass", or "fail: " and
#: the failing keys) and how the evaluation ended (0 and "" when it finished).
TAIL = ("gates", "exit_code", "error")
#: Markdown headers of the columns (units in brackets); an F-score's is ``F@0.05 m``.
HEADERS = {"name": "name", "rank": "rank", "map": "map", "truth": "truth",
           **{f.column: f.header for f in FIGURES if f.column},
           "gates": "gates", "exit_code": "exit code", "error": "error"}


def figures(doc: dict) -> dict[str, float | str | None]:
    """Every figure of a result's JSON document by name (:data:`FIGURES`, then the F-score at
    each tau); a document missing a figure that is not optional, or holding something else
    than a number there, is a ValueError naming its path."""
    for group in REQUIRED:
        _get(doc, group)
    values: dict[str, float | str | None] = {}
    for fig in FIGURES:
        if fig.path[0] == "distances_3d" and "distances_3d" not in doc:
            continue
        values[fig.name] = _read(doc, fig)
    for block, dim in (("distances", ""), ("distances_3d", "_3d")):
        if block == "distances" or block in doc:
            for f in _get(doc, block, "f_score"):
                tau = _number(f, "tau_m", "f_score")
                values[F_SCORE.format(dim=dim, tau=tau)] = _number(f, "f", "f_score")
    return values


def table_row(name: str, doc: dict) -> dict[str, object]:
    """One flat row of a result JSON document (``pcmapq eval --json``): the inputs' paths,
    every figure that has a column (:data:`HEAD`), the F-score at each tau and the verdict of
    its gates (:func:`gates_verdict`); exit_code 0, error ""; its rank None until the table's
    rows are ranked (:func:`ranked`). ValueError as :func:`figures`."""
    values = figures(doc)
    row: dict[str, object] = {"name": name, "rank": None, "map": _get(doc, "map", "path"),
                              "truth": _get(doc, "truth", "path")}
    row.update((f.column, values[f.name]) for f in FIGURES if f.column)
    for f in _get(doc, "distances", "f_score"):
        tau = f["tau_m"]
        row[F_SCORE_COLUMN.format(tau=tau)] = values[F_SCORE.format(dim="", tau=tau)]
    return {**row, "gates": gates_verdict(doc.get("gates")), "exit_code": 0, "error": ""}


def failed_row(name: str, map_path: str, truth_path: str, exit_code: int,
               error: str, verdict: str | None = None) -> dict[str, object]:
    """The row of an evaluation that failed: its inputs, exit code and one-line error, every
    figure None but the ``verdict`` of a map refused as another place."""
    row: dict[str, object] = dict.fromkeys(HEAD)
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
    """A table's columns: :data:`HEAD`, the F-score of every tau any row has (ascending),
    :data:`TAIL`."""
    taus = sorted({float(k[len("f_score@"):-1]) for row in rows for k in row
                   if k.startswith("f_score@")})
    return [*HEAD, *(F_SCORE_COLUMN.format(tau=t) for t in taus), *TAIL]


def _read(doc: dict, fig: Figure) -> float | str | None:
    """The figure's value in ``doc``: None where an optional figure's path stops."""
    *groups, key = fig.path
    node: object = doc
    for i, step in enumerate(groups):
        if not isinstance(node, dict) or node.get(step) is None:
            if fig.optional:
                return None
            raise ValueError(f"no '{'.'.join(groups[:i + 1])}'")
        node = node[step]
    if fig.optional and (not isinstance(node, dict) or node.get(key) is None):
        return None
    if not fig.number:
        return str(node[key])
    return _number(node, key, ".".join(groups))


def _get(doc: dict, *keys: str) -> object:
    """``doc[k0][k1]...``; a ValueError naming the dotted key when it is absent."""
    value: object = doc
    for i, key in enumerate(keys):
        if not isinstance(value, dict) or key not in value:
            raise ValueError(f"no '{'.'.join(keys[:i + 1])}'")
        value = value[key]
    return value


def _number(doc: object, key: str, where: str = "") -> float | None:
    """``doc[key]`` as a float, or None; a ValueError when it is absent or not a number."""
    if not isinstance(doc, dict) or key not in doc:
        raise ValueError(f"no '{where + '.' if where else ''}{key}'")
    value = doc[key]
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"'{where + '.' if where else ''}{key}' is not a number: {value!r}")
    return float(value)

