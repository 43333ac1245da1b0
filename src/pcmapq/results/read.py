"""A saved result's JSON document read back as a :class:`~pcmapq.results.result.Result`:
what the JSON does not hold is absent (rasters None, feature strengths and pair costs NaN)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pcmapq.core.frames import Frames
from pcmapq.core.grid import MetricGrid
from pcmapq.core.stats import Stats
from pcmapq.core.transform import Similarity2D
from pcmapq.features import Features
from pcmapq.match import Matching
from pcmapq.metrics.distances import Distances, FScore
from pcmapq.results.result import DetectorResult, Overlap, Result

if TYPE_CHECKING:
    from pcmapq.align.regions import Consistency


def _distances_of(doc: dict) -> Distances:
    return Distances(Stats.from_dict(doc["accuracy_m"]), Stats.from_dict(doc["completeness_m"]),
                     doc["chamfer_m"], tuple(FScore(**f) for f in doc["f_score"]),
                     doc.get("computed_on", ""))


def _xy(rows: list[dict], key: str) -> np.ndarray:
    """The ``key`` points of JSON rows as (N, 2) metres."""
    return np.array([r[key] for r in rows], dtype=np.float64).reshape(-1, 2)


def _unscored(doc: dict) -> str | None:
    """A detector's saved note when none of its scores is defined (it may have had nothing to
    find, which its counts alone do not tell); else None, the note follows from the counts."""
    return doc.get("note") if doc["quality"] is None and doc["precision"] is None else None


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
        missing=np.arange(n, n + k), extra=np.arange(n, n + e),
        unscored=_unscored(doc))
    return DetectorResult(Features(truth_xy, np.full(n + k, np.nan), t_strong),
                          Features(map_xy, np.full(n + e, np.nan), m_strong), matching)


def result_of(doc: dict) -> Result:
    """The :class:`Result` a parsed result document holds (:meth:`Result.from_json`)."""
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
                            a["method"], a["distinctiveness"], a.get("contradiction"),
                            a.get("free_on_truth"),
                            tuple((Similarity2D.from_dict(q), q["score"])
                                  for q in a.get("poses", ()))),
        overlap=Overlap(None, doc["coverage"], a["truth_recall"], a["agreement"],
                        a["confidence"], a["verdict"],
                        tuple(Part(**{**p, "centre_m": tuple(p["centre_m"]),
                                 "pose": Similarity2D.from_dict(p["pose"])})
                              for p in a["parts"]), a.get("seen_through")),
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
        map_message={k: v for k, v in doc["map"].items() if k not in ("path", "kind")} or None,
        consistency=_consistency_of(doc.get("consistency"), a["tolerance_m"]),
        rooms=doc.get("rooms"))




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


