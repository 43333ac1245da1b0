"""Result: everything a run found. The JSON, the table and the CSV are views of it."""

from __future__ import annotations

import io
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
from pcmapq.metrics.distances import Distances, FScore

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
        placed on their own agree with its pose) or OTHER.
    parts: the map's parts placed on their own (:mod:`pcmapq.align.parts`); empty when the
        confidence alone settled the verdict.
    """

    footprint: np.ndarray | None
    coverage: float
    truth_recall: float
    agreement: float
    confidence: float = 0.0
    verdict: str = SAME
    parts: tuple[Part, ...] = ()


@dataclass(frozen=True)
class Result:
    """A finished evaluation; all coordinates in the truth frame, metres.

    frames: the chain from each input to the truth's plan (levelling, 3D registration, the 2D
    alignment; :mod:`pcmapq.core.frames`). settings: the options it ran with
    (``Settings.to_dict()``, metres and degrees); command: the command line that made it
    (``pcmapq eval ...``, defaults left out), None from the library. noref: each input's
    no-reference figures, ``{"map": ..., "truth": ...}``
    (:func:`pcmapq.evaluation.noref_figures.input_figures`), None when not asked for.
    truth_sha256: the truth file's SHA-256 (hex; None from the library's
    :func:`~pcmapq.evaluation.pipeline.score`), so that results of one truth are known as such
    however its path was written.
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
        """The JSON document (see README): plain types, floats rounded to DECIMALS.
        ``features=False``: the figures alone, with the lists of matched, missing and extra
        features left empty (a figures row needs none of them; Intel's final map has about
        3000, and rounding them was most of the work)."""
        tf = self.transform
        x0, y0, yaw0 = self.grid.origin
        doc = {
            "pcmapq": {"version": __version__, "command": self.command},
            "settings": self.settings,
            "map": {"path": str(self.map_path), "kind": self.map_kind},
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
                          "agreement": self.overlap.agreement,
                          "distinctiveness": self.alignment.distinctiveness,
                          "confidence": self.overlap.confidence,
                          "verdict": self.overlap.verdict,
                          "parts": [{**asdict(p), "centre_m": list(p.centre_m),
                                     "pose": p.pose.to_dict()} for p in self.overlap.parts]},
            "consistency": _consistency_dict(self.consistency),
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
        doc = _rounded(doc)
        doc["noref"] = significant(self.noref)  # MPV, MOM: areas of 1e-3 m^2 and less
        return doc

    def to_json(self) -> str:
        """The JSON document, strict: a NaN or infinity in it is a ValueError, never bare
        ``NaN`` / ``Infinity`` (which JSON readers refuse)."""
        return json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n"

    @classmethod
    def from_json(cls, text: str) -> Result:
        """The Result that :meth:`to_json` wrote: ``from_json(r.to_json()).to_json() ==
        r.to_json()``. What the JSON does not hold is absent: the rasters are None, feature
        strengths and pair costs NaN, descriptors and segments None."""
        return _from_dict(json.loads(text))

    def vectors_csv(self) -> str:
        """One row per matched pair (the JSON's ``matches``): its truth and map features'
        positions and the displacement between them, metres (truth frame), then which of its
        two features are counted (1) or support-level (0). A pair counts towards ``matched``
        when its truth feature is counted and towards ``matched_map`` when its map feature
        is, so the rows outnumber either count when some pairs have one side uncounted."""
        out = io.StringIO()
        out.write("detector,truth_x_m,truth_y_m,map_x_m,map_y_m,dx_m,dy_m,displacement_m,"
                  "truth_counted,map_counted\n")
        for name, det in self.detectors.items():
            m = det.matching
            rows = np.column_stack([det.truth_xy, det.map_xy, m.displacement, det.distances])
            counted = np.column_stack([det.truth.strong[m.truth_idx], det.map.strong[m.map_idx]])
            for row, flags in zip(rows + 0.0, counted.astype(int), strict=True):
                out.write(",".join([name, *(f"{v:.{DECIMALS}f}" for v in row),
                                    *(str(f) for f in flags)]) + "\n")
        return out.getvalue()


    def regions_csv(self) -> str:
        """One row per region of the consistency map (the JSON's ``consistency.regions``):
        where the region is, the offset and turn that fit it to the truth on its own, its
        points and its fitness before and after, truth frame, metres and degrees."""
        out = io.StringIO()
        out.write(",".join(REGION_COLUMNS) + "\n")
        for row in _consistency_dict(self.consistency)["regions"]:
            out.write(",".join(str(int(v)) if isinstance(v, bool | int) else f"{v:.{DECIMALS}f}"
                               for v in (row[k] for k in REGION_COLUMNS)) + "\n")
        return out.getvalue()


#: The columns of a region, in the JSON and the regions CSV.
REGION_COLUMNS = ("x_m", "y_m", "dx_m", "dy_m", "offset_m", "turn_deg", "points",
                  "fitness_before", "fitness_after", "held")


def _consistency_dict(c: Consistency | None) -> dict:
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


def _consistency_of(doc: dict | None, tolerance: float) -> Consistency | None:
    """The consistency map read back from its JSON (None when there was none)."""
    from pcmapq.align.regions import Consistency

    if not doc or doc.get("tile_m") is None:
        return None
    rows = doc["regions"]

    def column(key: str, dtype=np.float64) -> np.ndarray:
        return np.array([r[key] for r in rows], dtype=dtype)

    return Consistency(doc["tile_m"], tolerance,
                       np.column_stack([column("x_m"), column("y_m")]).reshape(-1, 2),
                       np.column_stack([column("dx_m"), column("dy_m")]).reshape(-1, 2),
                       column("turn_deg"), column("points", int), column("fitness_before"),
                       column("fitness_after"), column("held", bool))


def _distances_dict(d: Distances) -> dict:
    return {"computed_on": d.basis, "accuracy_m": d.accuracy.to_dict(),
            "completeness_m": d.completeness.to_dict(), "chamfer_m": d.chamfer_m,
            "f_score": [asdict(f) for f in d.fscores]}


def _distances_of(doc: dict) -> Distances:
    return Distances(Stats.from_dict(doc["accuracy_m"]), Stats.from_dict(doc["completeness_m"]),
                     doc["chamfer_m"], tuple(FScore(**f) for f in doc["f_score"]),
                     doc.get("computed_on", ""))


def _xy(rows: list[dict], key: str) -> np.ndarray:
    """The ``key`` points of JSON rows as (N, 2) metres."""
    return np.array([r[key] for r in rows], dtype=np.float64).reshape(-1, 2)


def _detector_of(doc: dict, matches: list[dict], missing: list[dict],
                 extra: list[dict]) -> DetectorResult:
    """One detector read back: the truth's features are the matched ones then the missing
    ones, the map's the matched ones then the extra ones."""
    n, k, e = len(matches), len(missing), len(extra)
    t_strong = np.array([m["counted"]["truth"] for m in matches] + [True] * k, dtype=bool)
    m_strong = np.array([m["counted"]["map"] for m in matches] + [True] * e, dtype=bool)
    truth_xy = np.vstack([_xy(matches, "truth_xy_m"), _xy(missing, "truth_xy_m")])
    map_xy = np.vstack([_xy(matches, "map_xy_m"), _xy(extra, "map_xy_m")])
    pairs = np.arange(n)
    matching = Matching(
        truth_idx=pairs, map_idx=pairs, displacement=map_xy[:n] - truth_xy[:n],
        cost=np.full(n, np.nan), quality=doc["quality"], precision=doc["precision"],
        f1=doc["f1"], truth_features=doc["truth_features"], map_features=doc["map_features"],
        matched=doc["matched"], matched_map=doc["matched_map"],
        missing=np.arange(n, n + k), extra=np.arange(n, n + e))
    return DetectorResult(Features(truth_xy, np.full(n + k, np.nan), t_strong),
                          Features(map_xy, np.full(n + e, np.nan), m_strong), matching)


def _from_dict(doc: dict) -> Result:
    """:meth:`Result.from_json` of a parsed document."""
    from pcmapq.align import Alignment  # runtime imports: reading a 3D result loads Open3D
    from pcmapq.align.parts import Part
    from pcmapq.align.rigid3d import Registration3D

    a, t = doc["alignment"], doc["truth"]
    frames = Frames.from_dict(doc["frames"])
    origin = t["origin"]
    grid = MetricGrid(t["resolution_m"], (origin["x_m"], origin["y_m"],
                                          float(np.radians(origin["yaw_deg"]))),
                      tuple(t["shape"]))
    reg = doc.get("alignment_3d")
    detectors = {}
    for name, d in doc["detectors"].items():
        rows = {key: [r for r in doc[key] if r["detector"] == name]
                for key in ("matches", "missing", "extra")}
        detectors[name] = _detector_of(d, rows["matches"], rows["missing"], rows["extra"])
    return Result(
        map_path=Path(doc["map"]["path"]), map_kind=doc["map"]["kind"],
        truth_path=Path(t["path"]), truth_kind=t["kind"], grid=grid,
        alignment=Alignment(frames.planar, a["fitness"], a["rmse_m"], a["tolerance_m"],
                            a["method"], a["distinctiveness"]),
        overlap=Overlap(None, doc["coverage"], a["truth_recall"], a["agreement"],
                        a["confidence"], a["verdict"],
                        tuple(Part(**{**p, "centre_m": tuple(p["centre_m"]),
                                 "pose": Similarity2D.from_dict(p["pose"])})
                              for p in a["parts"])),
        distances=_distances_of(doc["distances"]),
        registration_3d=None if reg is None else Registration3D(
            np.asarray(reg["matrix"], dtype=np.float64), reg["fitness"], reg["rmse_m"]),
        distances_3d=_distances_of(doc["distances_3d"]) if "distances_3d" in doc else None,
        threshold=next((d["threshold_m"] for d in doc["detectors"].values()),
                       ((doc["settings"] or {}).get("matching") or {}).get("threshold", 0.5)),
        full=doc["scored_against"] == "whole truth", detectors=detectors,
        truth_occupied=None, map_occupied=None, frames=frames,
        footprint_rule=doc["footprint"], settings=doc["settings"],
        command=doc["pcmapq"]["command"], noref=doc.get("noref"), truth_sha256=t.get("sha256"),
        consistency=_consistency_of(doc.get("consistency"), a["tolerance_m"]))


def _rounded(value):
    """Round every float in a nested structure to DECIMALS (and turn -0.0 into 0.0)."""
    if isinstance(value, float):
        return round(value, DECIMALS) + 0.0
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_rounded(v) for v in value]
    return value
