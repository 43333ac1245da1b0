"""A result's figures, each under one name: the name a CI gate takes (``harris.quality``), the
path of the figure in the result's JSON, the column of the batch, compare and track tables
(``harris_quality``, kept as the tables have always been headed) and its markdown header. Every
reader of figures (gates, tables, track, compare, :meth:`Result.figures`) goes through
:data:`FIGURES` and :func:`figures`; the tables' rows are :mod:`pcmapq.results.rows`. Metres and
degrees; an undefined figure is None."""

from __future__ import annotations

import math
from dataclasses import dataclass

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
def by_name() -> dict[str, Figure]:
    """Every figure of :data:`FIGURES` by its name. This and the tables' rows
    (:mod:`pcmapq.results.rows`) read the table when called, so a figure added to it reaches
    every output."""
    return {f.name: f for f in FIGURES}


def figures(doc: dict) -> dict[str, float | str | None]:
    """Every figure of a result's JSON document by name (:data:`FIGURES`, then the F-score at
    each tau); a document missing a figure that is not optional, or holding something else
    than a number there, is a ValueError naming its path."""
    for group in REQUIRED:
        value_at(doc, group)
    values: dict[str, float | str | None] = {}
    for fig in FIGURES:
        if fig.path[0] == "distances_3d" and "distances_3d" not in doc:
            continue
        values[fig.name] = _read(doc, fig)
    for block, dim in (("distances", ""), ("distances_3d", "_3d")):
        if block == "distances" or block in doc:
            for f in value_at(doc, block, "f_score"):
                tau = _number(f, "tau_m", "f_score")
                for name, key in TAU_FIELDS.items():
                    values[AT_TAU.format(name=name, dim=dim, tau=tau)] = _number(f, key,
                                                                                "f_score")
    return values


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


def value_at(doc: dict, *keys: str) -> object:
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

