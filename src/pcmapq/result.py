"""Result: everything a run found. The JSON, the table and the CSV are views of it."""

from __future__ import annotations

import io
import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pcmapq import __version__
from pcmapq.features import Features
from pcmapq.grid import MetricGrid
from pcmapq.match import Matching
from pcmapq.metrics.distances import Distances

if TYPE_CHECKING:  # the alignment modules load Open3D; a Result only holds their outputs
    from pcmapq.align import Alignment
    from pcmapq.align.rigid3d import Registration3D

#: Decimals kept in saved numbers: micrometres, so reruns give byte-identical files.
DECIMALS = 6


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

    def displacement_stats(self) -> dict[str, float | None]:
        """mean, median, rmse and max of the displacement lengths, metres (None if no match)."""
        d = self.distances
        if len(d) == 0:
            return {"mean": None, "median": None, "rmse": None, "max": None}
        return {"mean": float(d.mean()), "median": float(np.median(d)),
                "rmse": float(np.sqrt(np.mean(d**2))), "max": float(d.max())}


@dataclass(frozen=True)
class Overlap:
    """What part of the truth the map covers and how well they agree there.

    footprint: (rows, cols) bool on the truth's grid, the area the map observed.
    coverage: share of the truth's occupied cells inside the footprint, [0, 1].
    truth_recall: share of those within the fit tolerance of a map occupied cell, [0, 1].
    agreement: alignment fitness times truth_recall.
    confidence: that the map shows the truth's place, [0, 1] (see pipeline.confidence); below
        0.5 a map of another place.
    """

    footprint: np.ndarray
    coverage: float
    truth_recall: float
    agreement: float
    confidence: float = 0.0


@dataclass(frozen=True)
class Result:
    """A finished evaluation; all coordinates in the truth frame, metres.

    settings: the options it ran with (``Settings.to_dict()``, metres and degrees); command: the
    command line that made it (``pcmapq eval ...``, defaults left out), None from the library.
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
    truth_occupied: np.ndarray
    map_occupied: np.ndarray
    footprint_rule: str = "known"
    settings: dict | None = None
    command: str | None = None

    def note(self, name: str) -> str | None:
        """Why detector ``name``'s quality, precision or f1 is undefined (None if defined)."""
        scope = "" if self.full else "inside the footprint"
        return self.detectors[name].matching.note(scope)

    def notes(self) -> list[str]:
        """One line per detector with an undefined score: ``name: n/a: why``."""
        return [f"{name}: n/a: {note}" for name in self.detectors
                if (note := self.note(name)) is not None]

    def to_dict(self) -> dict:
        """The JSON document (see README): plain types, floats rounded to DECIMALS."""
        tf = self.alignment.transform
        doc = {
            "pcmapq": {"version": __version__, "command": self.command},
            "settings": self.settings,
            "map": {"path": str(self.map_path), "kind": self.map_kind},
            "truth": {"path": str(self.truth_path), "kind": self.truth_kind,
                      "resolution_m": self.grid.resolution},
            "alignment": {"x_m": tf.tx, "y_m": tf.ty, "yaw_deg": tf.yaw_deg, "scale": tf.scale,
                          "matrix": tf.matrix.tolist(), "fitness": self.alignment.fitness,
                          "rmse_m": self.alignment.rmse_m,
                          "tolerance_m": self.alignment.tolerance_m,
                          "method": self.alignment.method,
                          "truth_recall": self.overlap.truth_recall,
                          "agreement": self.overlap.agreement,
                          "distinctiveness": self.alignment.distinctiveness,
                          "confidence": self.overlap.confidence},
            "coverage": self.overlap.coverage,
            "footprint": self.footprint_rule,
            "scored_against": "whole truth" if self.full else "footprint",
            "distances": _distances_dict(self.distances),
            "detectors": {},
            "matches": [], "missing": [], "extra": [],
        }
        if self.registration_3d is not None:
            reg = self.registration_3d
            doc["alignment_3d"] = {"matrix": reg.transform.tolist(), "fitness": reg.fitness,
                                   "rmse_m": reg.rmse}
            doc["distances_3d"] = _distances_dict(self.distances_3d)
        for name, det in self.detectors.items():
            m = det.matching
            doc["detectors"][name] = {
                "quality": m.quality, "precision": m.precision, "f1": m.f1,
                "note": self.note(name),
                "truth_features": m.truth_features, "map_features": m.map_features,
                "matched": m.matched, "threshold_m": self.threshold,
                "displacement_m": det.displacement_stats(),
            }
            doc["matches"] += [
                {"detector": name, "truth_xy_m": t, "map_xy_m": p, "displacement_m": d}
                for t, p, d in zip(det.truth_xy.tolist(), det.map_xy.tolist(),
                                   det.distances.tolist(), strict=True)]
            doc["missing"] += [{"detector": name, "truth_xy_m": t}
                               for t in det.truth.xy[m.missing].tolist()]
            doc["extra"] += [{"detector": name, "map_xy_m": p}
                             for p in det.map.xy[m.extra].tolist()]
        return _rounded(doc)

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2) + "\n"

    def vectors_csv(self) -> str:
        """One row per matched feature: truth and map position and displacement, metres."""
        out = io.StringIO()
        out.write("detector,truth_x_m,truth_y_m,map_x_m,map_y_m,dx_m,dy_m,displacement_m\n")
        for name, det in self.detectors.items():
            rows = np.column_stack([det.truth_xy, det.map_xy, det.matching.displacement,
                                    det.distances])
            np.savetxt(out, rows + 0.0, fmt=",".join([name] + [f"%.{DECIMALS}f"] * 7))
        return out.getvalue()


def _distances_dict(d: Distances) -> dict:
    return {"accuracy_m": asdict(d.accuracy), "completeness_m": asdict(d.completeness),
            "chamfer_m": d.chamfer_m, "f_score": [asdict(f) for f in d.fscores]}


def _rounded(value):
    """Round every float in a nested structure to DECIMALS (and turn -0.0 into 0.0)."""
    if isinstance(value, float):
        return round(value, DECIMALS) + 0.0
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_rounded(v) for v in value]
    return value
