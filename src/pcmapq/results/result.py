"""Result: everything a run found. The JSON, the table and the CSV are views of it."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pcmapq import __version__
from pcmapq.core.frames import Frames
from pcmapq.core.grid import MetricGrid
from pcmapq.core.stats import Stats, significant
from pcmapq.core.transform import Similarity2D
from pcmapq.features import Features
from pcmapq.match import Matching
from pcmapq.metrics.distances import Distances

if TYPE_CHECKING:  # the alignment modules load Open3D; a Result only holds their outputs
    from pcmapq.align import Alignment
    from pcmapq.align.parts import Part
    from pcmapq.align.regions import Consistency
    from pcmapq.align.rigid3d import Registration3D

#: Decimals kept in saved numbers: micrometres, so reruns give byte-identical files.
DECIMALS = 6
#: The verdicts on whether a map shows the truth's place (see
#: :mod:`pcmapq.evaluation.same_place`): one pose fits it; it is of the truth's place but no
#: single pose fits it whole (scored); it shows another place (refused unless ``--force``).
SAME, INCONSISTENT, OTHER = "same place", "same place, inconsistent map", "another place"
#: A map with free space placed below the minimum confidence where nothing it saw contradicts
#: the truth: scored, and flagged with the search's two best poses (it may show the truth's
#: place or another that looks alike; nothing it holds tells which).
LOW = "placed with low confidence"


@dataclass(frozen=True)
class DetectorResult:
    """One detector's features on both sides (truth frame, metres) and their matching."""

    truth: Features
    map: Features
    matching: Matching

    @property
    def truth_xy(self) -> np.ndarray:
        """Matched truth features, (M, 2) metres."""
        return self.truth.xy[self.matching.truth_idx]

    @property
    def map_xy(self) -> np.ndarray:
        """Where each matched truth feature is in the map: truth_xy + displacement, (M, 2) m."""
        return self.truth_xy + self.matching.displacement

    @property
    def distances(self) -> np.ndarray:
        """Length of each displacement, (M,) metres."""
        return np.linalg.norm(self.matching.displacement, axis=1)

    def displacement_stats(self) -> Stats:
        """Statistics of the displacement lengths, metres (undefined with no match)."""
        return Stats.of(self.distances)


@dataclass(frozen=True)
class Overlap:
    """What part of the truth the map covers and how well they agree there.

    footprint: (rows, cols) bool on the truth's grid, the area the map observed (None in a
        result read back from JSON).
    coverage: share of the truth's occupied cells inside the footprint, [0, 1].
    truth_recall: share of those within the fit tolerance of a map occupied cell, [0, 1].
    agreement: alignment fitness times truth_recall.
    confidence: that one pose places the map on the truth's place, [0, 1] (see
        same_place.confidence).
    verdict: SAME (confidence at least the minimum), INCONSISTENT (below it, but its parts
        placed on their own agree with its pose), LOW (below it, a map with free space that saw
        through few of the truth's walls) or OTHER.
    parts: the map's parts placed on their own (:mod:`pcmapq.align.parts`); empty when the
        confidence alone settled the verdict.
    seen_through: for a map with free space, the share of the truth's wall faces inside the
        footprint that lie on the map's free cells farther than
        :data:`~pcmapq.align.free_space.CLEAR_M` from its walls: walls the map saw through,
        [0, 1]; None for a map without free space.
    """

    footprint: np.ndarray | None
    coverage: float
    truth_recall: float
    agreement: float
    confidence: float = 0.0
    verdict: str = SAME
    parts: tuple[Part, ...] = ()
    seen_through: float | None = None


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
        """The JSON document (docs/formats.md): plain types, floats rounded to DECIMALS.
        ``features=False``: the figures alone, with the lists of matched, missing and extra
        features left empty (a figures row needs none of them, and a large map's thousands of
        features would be most of the work of rounding)."""
        tf = self.transform
        x0, y0, yaw0 = self.grid.origin
        doc = {
            "pcmapq": {"version": __version__, "command": self.command},
            "settings": self.settings,
            "map": {"path": str(self.map_path), "kind": self.map_kind,
                    **(self.map_message or {})},
            "truth": {"path": str(self.truth_path), "kind": self.truth_kind,
                      "resolution_m": self.grid.resolution,
                      "origin": {"x_m": x0, "y_m": y0, "yaw_deg": float(np.degrees(yaw0))},
                      "shape": list(self.grid.shape),
                      **({} if self.truth_sha256 is None else {"sha256": self.truth_sha256})},
            "alignment": {**tf.to_dict(), "matrix": tf.matrix.tolist(),
                          "fitness": self.alignment.fitness,
                          "rmse_m": self.alignment.rmse_m,
                          "tolerance_m": self.alignment.tolerance_m,
                          "method": self.alignment.method,
                          "truth_recall": self.overlap.truth_recall,
                          "seen_through": self.overlap.seen_through,
                          "agreement": self.overlap.agreement,
                          "distinctiveness": self.alignment.distinctiveness,
                          "contradiction": self.alignment.contradiction,
                          "free_on_truth": self.alignment.free_on_truth,
                          "poses": [{**tf.to_dict(), "score": score}
                                    for tf, score in self.alignment.poses],
                          "confidence": self.overlap.confidence,
                          "verdict": self.overlap.verdict,
                          "parts": [{**asdict(p), "centre_m": list(p.centre_m),
                                     "pose": p.pose.to_dict()} for p in self.overlap.parts]},
            "consistency": consistency_dict(self.consistency),
            "frames": self.frames.to_dict(),
            "coverage": self.overlap.coverage,
            "footprint": self.footprint_rule,
            "scored_against": "whole truth" if self.full else "footprint",
            "distances": _distances_dict(self.distances),
            "noref": None,
            "detectors": {},
            "matches": [], "missing": [], "extra": [],
        }
        if self.registration_3d is not None:
            reg = self.registration_3d
            doc["alignment_3d"] = {"matrix": reg.transform.tolist(), "fitness": reg.fitness,
                                   "rmse_m": reg.rmse_m}
            doc["distances_3d"] = _distances_dict(self.distances_3d)
        for name, det in self.detectors.items():
            m = det.matching
            doc["detectors"][name] = {
                "quality": m.quality, "precision": m.precision, "f1": m.f1,
                "note": self.note(name),
                "truth_features": m.truth_features, "map_features": m.map_features,
                "matched": m.matched, "matched_map": m.matched_map,
                "threshold_m": self.threshold,
                "displacement_m": det.displacement_stats().to_dict(),
            }
            if not features:
                continue
            doc["matches"] += [
                {"detector": name, "truth_xy_m": t, "map_xy_m": p, "displacement_m": d,
                 "counted": {"truth": ts, "map": ms}}
                for t, p, d, ts, ms in zip(
                    det.truth_xy.tolist(), det.map_xy.tolist(), det.distances.tolist(),
                    det.truth.strong[m.truth_idx].tolist(), det.map.strong[m.map_idx].tolist(),
                    strict=True)]
            doc["missing"] += [{"detector": name, "truth_xy_m": t}
                               for t in det.truth.xy[m.missing].tolist()]
            doc["extra"] += [{"detector": name, "map_xy_m": p}
                             for p in det.map.xy[m.extra].tolist()]
        if self.rooms is not None:
            doc["rooms"] = self.rooms
        doc = rounded(doc)
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
        NaN, descriptors and segments None."""
        from pcmapq.results.read import result_of

        is_text = isinstance(source, str) and source.lstrip().startswith("{")
        text = source if is_text else Path(source).read_text(encoding="utf-8")
        return result_of(json.loads(text))

    def figures(self) -> dict[str, float | str | None]:
        """Every figure by its one name (``harris.quality``, ``accuracy.mean``, ``coverage``,
        ``alignment.confidence``, ``f_score@0.05`` ...; :mod:`pcmapq.results.figures`), as
        gates, tables, track and compare read them: metres and degrees, None when undefined."""
        from pcmapq.results.figures import figures

        return figures(self.to_dict(features=False))

    def vectors_csv(self) -> str:
        """The vectorial map as CSV, one row per matched pair
        (:func:`pcmapq.results.csv_files.vectors_csv`)."""
        from pcmapq.results.csv_files import vectors_csv

        return vectors_csv(self)

    def regions_csv(self) -> str:
        """The consistency map as CSV, one row per region
        (:func:`pcmapq.results.csv_files.regions_csv`)."""
        from pcmapq.results.csv_files import regions_csv

        return regions_csv(self)


#: The columns of a region, in the JSON and the regions CSV.
REGION_COLUMNS = ("x_m", "y_m", "dx_m", "dy_m", "offset_m", "turn_deg", "points",
                  "fitness_before", "fitness_after", "held")


def consistency_dict(c: Consistency | None) -> dict:
    """The consistency map as JSON: the tile, the largest held offset and where, the map's
    fitness at its pose and with each region aligned on its own, and the regions."""
    if c is None:
        return {"tile_m": None, "largest_offset_m": None, "largest_at_m": None,
                "global_fitness": None, "local_fitness": None, "regions": []}
    k = c.largest()
    regions = [dict(zip(REGION_COLUMNS, (float(x), float(y), float(dx), float(dy), float(o),
                                          float(t), int(n), float(b), float(a), bool(h)),
                        strict=True))
               for (x, y), (dx, dy), o, t, n, b, a, h in zip(
                   c.centre, c.offset, c.offset_m, c.turn_deg, c.points, c.fit_before,
                   c.fit_after, c.held, strict=True)]
    return {"tile_m": c.tile_m, "largest_offset_m": None if k is None else float(c.offset_m[k]),
            "largest_at_m": None if k is None else [float(v) for v in c.centre[k]],
            "global_fitness": c.global_fitness(), "local_fitness": c.local_fitness(),
            "regions": regions}


def _distances_dict(d: Distances) -> dict:
    return {"computed_on": d.basis, "accuracy_m": d.accuracy.to_dict(),
            "completeness_m": d.completeness.to_dict(), "chamfer_m": d.chamfer_m,
            "f_score": [asdict(f) for f in d.fscores]}


def rounded(value):
    """Round every float in a nested structure to DECIMALS (and turn -0.0 into 0.0)."""
    if isinstance(value, float):
        return round(value, DECIMALS) + 0.0
    if isinstance(value, dict):
        return {k: rounded(v) for k, v in value.items()}
    if isinstance(value, list):
        return [rounded(v) for v in value]
    return value
