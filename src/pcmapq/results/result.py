"""Result: everything a run found. The JSON, the table and the CSV are views of it."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from pcmapq.core.stats import significant
from pcmapq.results import csv_files, document
from pcmapq.results import figures as figure_table
from pcmapq.results.blocks import (  # noqa: F401  (the names every reader imports from here)
    DECIMALS,
    INCONSISTENT,
    LOW,
    OTHER,
    SAME,
    DetectorResult,
    Findings,
    Overlap,
    rounded,
)
from pcmapq.results.document import REGION_COLUMNS  # noqa: F401
from pcmapq.results.schema import ResultDocument


@dataclass(frozen=True)
class Result(Findings):
    """A finished evaluation (:class:`~pcmapq.results.blocks.Findings`, whose fields it has)
    and its views: the JSON document, the figures by name, the CSV files."""

    def to_dict(self, features: bool = True) -> dict:
        """The JSON document (:class:`~pcmapq.results.schema.ResultDocument`, docs/formats.md):
        plain types, floats rounded to DECIMALS. ``features=False``: the figures alone, with
        the lists of matched, missing and extra features left empty (a figures row needs
        none of them)."""
        doc = rounded(document.document(self, features).model_dump(exclude_unset=True))
        doc["noref"] = significant(self.noref)  # MPV, MOM: areas of 1e-3 m^2 and less
        return doc

    def to_json(self) -> str:
        """The JSON document, strict: a NaN or infinity in it is a ValueError, never bare
        ``NaN`` / ``Infinity`` (which JSON readers refuse)."""
        return json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n"

    @classmethod
    def from_json(cls, source: str | Path) -> Result:
        """The Result that :meth:`to_json` wrote: ``from_json(r.to_json()).to_json() ==
        r.to_json()``. ``source`` is the JSON text (a str starting with ``{``) or the path of
        a file holding it (a Path, or any other str), as ``--json FILE`` writes it. What the
        JSON does not hold is absent: the rasters are None, feature strengths and pair costs
        NaN, descriptors and segments None. A document that does not follow the schema is a
        pydantic ValidationError (a ValueError)."""
        is_text = isinstance(source, str) and source.lstrip().startswith("{")
        text = source if is_text else Path(source).read_text(encoding="utf-8")
        return cls(**document.fields(ResultDocument.model_validate_json(text)))

    def figures(self) -> dict[str, float | str | None]:
        """Every figure by its one name (``harris.quality``, ``accuracy.mean``, ``coverage``,
        ``alignment.confidence``, ``f_score@0.05`` ...; :mod:`pcmapq.results.figures`), as
        gates, tables, track and compare read them: metres and degrees, None when undefined."""
        return figure_table.figures(self.to_dict(features=False))

    def vectors_csv(self) -> str:
        """The vectorial map as CSV, one row per matched pair
        (:func:`pcmapq.results.csv_files.vectors_csv`)."""
        return csv_files.vectors_csv(self)

    def regions_csv(self) -> str:
        """The consistency map as CSV, one row per region
        (:func:`pcmapq.results.csv_files.regions_csv`)."""
        return csv_files.regions_csv(self)

    def regions_3d_csv(self) -> str:
        """The 3D consistency map as CSV, one row per region
        (:func:`pcmapq.results.csv_files.regions_3d_csv`)."""
        return csv_files.regions_3d_csv(self)
