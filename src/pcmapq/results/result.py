"""Result: everything a run found. The JSON, the table and the CSV are views of it."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pcmapq.core.frames import Frames
from pcmapq.core.grid import MetricGrid
from pcmapq.core.stats import significant
from pcmapq.core.transform import Similarity2D
from pcmapq.metrics.distances import Distances
from pcmapq.metrics.map_gaussians import MapGaussians
from pcmapq.results import csv_files, document
from pcmapq.results import figures as figure_table
from pcmapq.results.blocks import (  # noqa: F401  (the names every reader imports from here)
    DECIMALS,
    INCONSISTENT,
    LOW,
    OTHER,
    SAME,
    DetectorResult,
    Overlap,
    rounded,
)
from pcmapq.results.document import REGION_COLUMNS  # noqa: F401
from pcmapq.results.schema import ResultDocument

if TYPE_CHECKING:  # the alignment modules load Open3D; a Result only holds their outputs
    from pcmapq.align import Alignment
    from pcmapq.align.regions import Consistency
    from pcmapq.align.rigid3d import Registration3D


@dataclass(frozen=True)
class Result:
    """A finished evaluation; all coordinates in the truth frame, metres.

    frames: the chain from each input to the truth's plan (levelling, 3D registration, the 2D
    alignment; :mod:`pcmapq.core.frames`). settings: the options it ran with
    (``Settings.to_dict()``, metres and degrees); command: the command line that made it
    (``pcmapq eval ...``, defaults left out), None from the library. noref: each input's
    no-reference figures, ``{"map": ..., "truth": ...}``
    (:func:`pcmapq.evaluation.noref_figures.input_figures`), None when not asked for.
    truth_sha256: the truth file's SHA-256 (hex; None for a result made without its file), so
    that results of one truth are known as such however its path was written. rooms: the
    rooms detector's rooms, each with its status (:func:`pcmapq.match.rooms.room_table`), None
    when it did not run. map_message: the recording's message the map was read from (topic,
    index, ``time_s`` from the recording's start, header ``stamp_s``), None for a file.
    map_3d: MapEval's AWD and SCS of two 3D clouds in one frame
    (:mod:`pcmapq.metrics.map_gaussians`), None otherwise.
    truth_occupied, map_occupied (and the overlap's footprint): the rasters on ``grid``; None
    in a result read back by :meth:`from_json`, which holds everything the JSON holds and no
    more.
    """

    map_path: Path
    map_kind: str
    truth_path: Path
    truth_kind: str
    grid: MetricGrid
    alignment: Alignment
    overlap: Overlap
    distances: Distances
    registration_3d: Registration3D | None
    distances_3d: Distances | None
    threshold: float
    full: bool
    detectors: dict[str, DetectorResult]
    truth_occupied: np.ndarray | None
    map_occupied: np.ndarray | None
    frames: Frames
    footprint_rule: str = "known"
    settings: dict | None = None
    command: str | None = None
    noref: dict | None = None
    consistency: Consistency | None = None
    truth_sha256: str | None = None
    rooms: dict | None = None
    map_message: dict | None = None
    map_3d: MapGaussians | None = None

    @property
    def transform(self) -> Similarity2D:
        """The map -> truth transform in the plane (``p_truth = s * R(yaw) * p_map + t``): the
        2D alignment after the 3D registration's planar part, when there is one."""
        return self.frames.map_to_truth()

    def note(self, name: str) -> str | None:
        """Why detector ``name``'s quality, precision or f1 is undefined (None if defined)."""
        scope = "" if self.full else "inside the footprint"
        return self.detectors[name].matching.note(scope)

    def notes(self) -> list[str]:
        """One line per detector with an undefined score: ``name: n/a: why``."""
        return [f"{name}: n/a: {note}" for name in self.detectors
                if (note := self.note(name)) is not None]

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
