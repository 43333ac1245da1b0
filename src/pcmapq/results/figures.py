"""A result's figures, each under one name: the name a CI gate takes (``harris.quality``), the
path of the figure in the result's JSON, the column of the batch, compare and track tables
(``harris_quality``, kept as the tables have always been headed) and its markdown header. Every
reader of figures (gates, tables, track, compare, :meth:`Result.figures`) goes through
:data:`FIGURES` and :func:`figures`. Metres and degrees; an undefined figure is None."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pcmapq.core.stats import FIELDS as STAT_FIELDS
from pcmapq.features.names import STRUCTURE_NAMES
from pcmapq.settings import DETECTOR_NAMES

#: A detector's scores, each in [0, 1], in table order.
SCORES = ("quality", "precision", "f1")
#: The figures of ``alignment`` a gate reaches by their own JSON name.
ALIGNMENT_FIELDS = ("confidence", "fitness", "rmse_m", "truth_recall", "seen_through",
                    "agreement", "distinctiveness", "contradiction", "free_on_truth", "x_m",
                    "y_m", "yaw_deg", "scale")


#: Units a figure's JSON key ends with, and how a header writes them.
UNITS = {"_m": "m", "_deg": "deg"}


@dataclass(frozen=True)
class Figure:
    """One figure: its ``name`` (gates, :meth:`Result.figures`, track) and its ``path`` in the
    result's JSON. ``column``: whether it is a column of the batch, compare and track tables;
    the column's name and markdown header follow from the path (:attr:`column_name`,
    :attr:`header`; ``label`` overrides the header's words). ``optional``: a result without
    it reads None (a detector not run, a result without a consistency map); otherwise a
    document without it is not a result. ``number``: False for a word (the verdict), which
    no gate reads. ``sparse``: a column only of the tables where some row has it (a figure of
    two 3D clouds), so a table of 2D maps keeps its columns. ``column_words``: the column's
    name without its unit, when the path's words name another figure's column (the 3D
    consistency map's beside the 2D one's)."""

    name: str
    path: tuple[str, ...]
    column: bool = False
    label: str | None = None
    optional: bool = False
    number: bool = True
    sparse: bool = False
    column_words: str | None = None

    @property
    def unit(self) -> str:
        """The figure's unit, "m", "deg" or "" (a share, a count, a word), from its path."""
        return next((u for key in self.path for end, u in UNITS.items() if key.endswith(end)),
                    "")

    @property
    def words(self) -> tuple[str, ...]:
        """The path below its group (``detectors``, ``distances``, ``alignment``, ...) with
        the unit left out: ``("accuracy", "mean")``."""
        keys = self.path[1:] if len(self.path) > 1 else self.path
        return tuple(next((k[:-len(e)] for e in UNITS if k.endswith(e)), k) for k in keys)

    @property
    def column_name(self) -> str | None:
        """Its table column (``harris_quality``, ``accuracy_mean_m``, ``yaw_deg``), None when
        it is not a column."""
        if not self.column:
            return None
        words = self.column_words or "_".join(self.words)
        return words + (f"_{self.unit}" if self.unit else "")

    @property
    def short(self) -> str:
        """Its header in a narrow terminal table: the first word, the unit below it
        (``accuracy`` over ``(m)``)."""
        return self.words[0] + (f"\n({self.unit})" if self.unit else "")

    @property
    def header(self) -> str:
        """Its markdown header, the unit in brackets: ``accuracy mean (m)``."""
        words = self.label or " ".join(self.words)
        return f"{words} ({self.unit})" if self.unit else words


def _stats(side: str, block: str, suffix: str) -> list[Figure]:
    """``accuracy.mean`` ...: every statistic of one side's distances (mean and median are
    table columns of the 2D distances)."""
    return [Figure(f"{side}{suffix}.{s}", (block, f"{side}_m", s),
                   column=not suffix and s in ("mean", "median"),
                   optional=bool(suffix) or s not in ("mean", "median"))
            for s in STAT_FIELDS]


#: Every named figure, table columns in table order first.
FIGURES: tuple[Figure, ...] = (
    *(Figure(f"{d}.{s}", ("detectors", d, s), column=True, optional=True)
      for s in SCORES for d in DETECTOR_NAMES),
    *(Figure(f"{d}.{s}", ("structures_3d", d, s), column=True, optional=True, sparse=True)
      for s in SCORES for d in STRUCTURE_NAMES),
    Figure("coverage", ("coverage",), column=True),
    Figure("alignment.fitness", ("alignment", "fitness"), column=True),
    Figure("alignment.confidence", ("alignment", "confidence"), column=True),
    Figure("alignment.verdict", ("alignment", "verdict"), column=True, optional=True,
           number=False),
    Figure("alignment.x_m", ("alignment", "x_m"), column=True),
    Figure("alignment.y_m", ("alignment", "y_m"), column=True),
    Figure("alignment.yaw_deg", ("alignment", "yaw_deg"), column=True),
    Figure("alignment.scale", ("alignment", "scale"), column=True),
    Figure("consistency.largest_offset_m", ("consistency", "largest_offset_m"), column=True,
           label="largest region offset", optional=True),
    Figure("consistency_3d.largest_offset_m", ("consistency_3d", "largest_offset_m"),
           column=True, label="largest region offset 3D", optional=True, sparse=True,
           column_words="largest_offset_3d"),
    Figure("consistency_3d.largest_dz_m", ("consistency_3d", "largest_dz_m"), column=True,
           label="largest region dz", optional=True, sparse=True),
    *(f for f in _stats("accuracy", "distances", "") if f.column),
    *(f for f in _stats("completeness", "distances", "") if f.column),
    Figure("chamfer", ("distances", "chamfer_m"), column=True, label="Chamfer"),
    *(f for f in _stats("accuracy", "distances", "") if not f.column),
    *(f for f in _stats("completeness", "distances", "") if not f.column),
    *(Figure(f"alignment.{a}", ("alignment", a), optional=True) for a in ALIGNMENT_FIELDS
      if a not in ("confidence", "fitness", "x_m", "y_m", "yaw_deg", "scale")),
    *_stats("accuracy", "distances_3d", "_3d"), *_stats("completeness", "distances_3d", "_3d"),
    Figure("chamfer_3d", ("distances_3d", "chamfer_m"), optional=True, label="Chamfer 3D"),
    Figure("awd_3d", ("map_3d", "awd_m"), column=True, label="AWD", optional=True, sparse=True),
    Figure("scs_3d", ("map_3d", "scs"), column=True, label="SCS", optional=True, sparse=True),
    *(Figure(f"{d}.{k}.{s}", ("structures_3d", d, f"{k}_{u}", s), optional=True)
      for d in STRUCTURE_NAMES for k, u in (("displacement", "m"), ("angle", "deg"))
      for s in ("mean", "max")),
)
#: Other names of figures that gates have always read: the one list of aliases.
ALIASES = {"chamfer.mean": "chamfer", "chamfer_3d.mean": "chamfer_3d"}
#: The figures measured at each tau of the result, by name, and their key in an F-score's
#: block: the F-score, and the wall precision (share of the map's walls within tau of a
#: truth wall). ``f_score@0.05``, ``wall_precision_3d@0.1`` ...
TAU_FIELDS = {"f_score": "f", "wall_precision": "precision"}
#: The figure that dates a fault over a run (``pcmapq track``): the detectors' mean precision,
#: is what the map shows right?
MEAN_PRECISION = "precision"
#: Detectors whose precision :data:`MEAN_PRECISION` leaves out. A room of a growing map is
#: right only once the robot has drawn its walls whole: until then it leaks into the next
#: room or stops at the map's edge, so the rooms' precision falls with exploration alone and
#: would date a fault where there is none. Their own columns stay in every step.
NOT_IN_PRECISION = ("rooms",)
#: The groups every result has (a document without one is not a result).
REQUIRED = ("map", "truth", "detectors", "alignment", "distances")
#: A figure at one tau: its name and its column (``f_score@0.05``, ``f_score@0.05m``);
#: ``f_score_3d@TAU`` for two 3D clouds.
AT_TAU, AT_TAU_COLUMN = "{name}{dim}@{tau:g}", "{name}@{tau:g}m"
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


def by_name() -> dict[str, Figure]:
    """Every figure of :data:`FIGURES` by its name. This and the tables below read the table
    when called, so a figure added to it reaches every output."""
    return {f.name: f for f in FIGURES}


def head() -> tuple[str, ...]:
    """Columns before the F-scores: :data:`INPUTS`, then every figure that has a column."""
    return (*INPUTS, *(f.column_name for f in FIGURES if f.column))


def header(column: str) -> str:
    """A column's markdown header (units in brackets); an F-score's is its column."""
    figure = next((f for f in FIGURES if f.column and f.column_name == column), None)
    return figure.header if figure else OTHER_HEADERS.get(column, column)


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
                for name, key in TAU_FIELDS.items():
                    values[AT_TAU.format(name=name, dim=dim, tau=tau)] = _number(f, key,
                                                                                "f_score")
    return values


def step_columns(doc: dict, precisions: dict[str, float | None]) -> dict[str, float | None]:
    """The columns a step of ``pcmapq track`` adds to :func:`table_row`'s: the detectors'
    mean precision (:data:`MEAN_PRECISION`, of ``precisions`` by detector, unrounded) and the
    wall precision at each tau (``wall_precision@0.1m``)."""
    values = figures(doc)
    kept = [p for d, p in precisions.items() if p is not None and d not in NOT_IN_PRECISION]
    columns: dict[str, float | None] = {
        MEAN_PRECISION: float(np.mean(kept)) if kept else None}
    for f in _get(doc, "distances", "f_score"):
        name = AT_TAU.format(name="wall_precision", dim="", tau=f["tau_m"])
        columns[AT_TAU_COLUMN.format(name="wall_precision", tau=f["tau_m"])] = values[name]
    return columns


def table_row(name: str, doc: dict) -> dict[str, object]:
    """One flat row of a result JSON document (``pcmapq eval --json``): the inputs' paths,
    every figure that has a column (:func:`head`), the F-score at each tau and the verdict of
    its gates (:func:`gates_verdict`); exit_code 0, error ""; its rank None until the table's
    rows are ranked (:func:`ranked`). ValueError as :func:`figures`."""
    values = figures(doc)
    row: dict[str, object] = {"name": name, "rank": None, "map": _get(doc, "map", "path"),
                              "truth": _get(doc, "truth", "path")}
    row.update((f.column_name, values[f.name]) for f in FIGURES
               if f.column and not (f.sparse and values[f.name] is None))
    for f in _get(doc, "distances", "f_score"):
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
    return {f.column_name for f in FIGURES if f.column and f.sparse}


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

