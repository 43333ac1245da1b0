"""The 3D structures of a result (:class:`~pcmapq.match.structures.Structures3D`) as the
document's ``structures_3d`` block (:mod:`pcmapq.results.schema.structures`) and back. Read
back, each side's structures are its matched ones, then the truth's missing ones or the map's
extra ones."""

from __future__ import annotations

import numpy as np

from pcmapq.core.stats import Stats
from pcmapq.features.lines3d import Lines
from pcmapq.features.planes3d import Planes
from pcmapq.match.plane_fit import PlaneFit
from pcmapq.match.structures import (
    NOUNS,
    StructureMatching,
    StructureResult,
    Structures3D,
)
from pcmapq.results.schema import structures as s


def _plane(p: Planes, k: int) -> s.Plane3D:
    return s.Plane3D(normal=tuple(p.normal[k].tolist()), offset_m=float(p.offset[k]),
                     centroid_m=tuple(p.centroid[k].tolist()),
                     corners_m=tuple(tuple(c) for c in p.corners[k].tolist()),
                     extent_m=tuple(p.extent[k].tolist()), area_m2=float(p.area[k]),
                     points=int(p.points[k]))


def _line(lines: Lines, k: int) -> s.Line3D:
    return s.Line3D(direction=tuple(lines.direction[k].tolist()),
                    point_m=tuple(lines.point[k].tolist()), length_m=float(lines.length[k]))


def _scores(name: str, found: StructureResult, result: Structures3D, features: bool) -> dict:
    """A detector's block as keyword arguments (its lists empty unless ``features``)."""
    m = found.matching
    one = _plane if name == "planes" else _line
    pair = s.PlaneMatch if name == "planes" else s.LineMatch
    lists = {"matches": [], "missing": [], "extra": []}
    if features:
        lists = {"matches": [pair(truth=one(found.truth, int(t)), map=one(found.map, int(j)),
                                  displacement_m=float(d), angle_deg=float(a))
                             for t, j, d, a in zip(m.truth_idx, m.map_idx, m.displacement,
                                                   m.angle, strict=True)],
                 "missing": [one(found.truth, int(k)) for k in m.missing],
                 "extra": [one(found.map, int(k)) for k in m.extra]}
    return dict(quality=m.quality, precision=m.precision, f1=m.f1, note=m.note(NOUNS[name]),
                truth_structures=m.truth_structures, map_structures=m.map_structures,
                matched=m.matched, max_angle_deg=result.max_angle,
                max_offset_m=result.max_offset, displacement_m=Stats.of(np.abs(m.displacement)),
                angle_deg=Stats.of(m.angle), **lists)


def _fit(fit: PlaneFit) -> s.PlaneFit3D:
    return s.PlaneFit3D(applied=fit.applied, matrix=fit.fitted.tolist(),
                        centre_m=tuple(fit.centre.tolist()), offset_m=fit.offset,
                        angle_deg=fit.angle, largest_move_m=fit.largest_move,
                        reach_m=fit.reach, planes_held=fit.held, planes_matched=fit.pairs)


def structures_block(result: Structures3D, features: bool = True) -> s.Structures3D:
    """The ``structures_3d`` block; ``features=False``: the scores alone, every list empty."""
    d = result.detectors
    fit = {} if result.fit is None else {"fit": _fit(result.fit)}
    return s.Structures3D(planes=s.PlaneScores(**_scores("planes", d["planes"], result,
                                                         features)),
                          plane_lines=s.LineScores(**_scores("plane_lines", d["plane_lines"],
                                                             result, features)), **fit)


def _fit_of(doc: s.PlaneFit3D | None) -> PlaneFit | None:
    if doc is None:
        return None
    return PlaneFit(np.array(doc.matrix, dtype=np.float64), np.array(doc.centre_m),
                    doc.planes_held, doc.planes_matched, doc.largest_move_m, doc.reach_m)


def _planes_of(rows: list[s.Plane3D]) -> Planes:
    def column(key: str, shape: tuple[int, ...]) -> np.ndarray:
        return np.array([getattr(r, key) for r in rows], dtype=np.float64).reshape(shape)

    n = len(rows)
    return Planes(column("normal", (n, 3)), column("offset_m", (n,)),
                  column("centroid_m", (n, 3)), column("corners_m", (n, 4, 3)),
                  column("extent_m", (n, 2)), column("area_m2", (n,)),
                  np.array([r.points for r in rows], dtype=np.int64))


def _lines_of(rows: list[s.Line3D]) -> Lines:
    n = len(rows)
    return Lines(np.array([r.direction for r in rows], dtype=np.float64).reshape(n, 3),
                 np.array([r.point_m for r in rows], dtype=np.float64).reshape(n, 3),
                 np.array([r.length_m for r in rows], dtype=np.float64))


def _result_of(name: str, doc: s.PlaneScores | s.LineScores) -> StructureResult:
    """One detector read back: matched structures first on both sides."""
    rows = _planes_of if name == "planes" else _lines_of
    n, k, e = len(doc.matches), len(doc.missing), len(doc.extra)
    pairs = np.arange(n)
    matching = StructureMatching(
        pairs, pairs, np.array([m.displacement_m for m in doc.matches], dtype=np.float64),
        np.array([m.angle_deg for m in doc.matches], dtype=np.float64), doc.quality,
        doc.precision, doc.f1, doc.truth_structures, doc.map_structures,
        np.arange(n, n + k), np.arange(n, n + e),
        doc.note if doc.quality is None and doc.precision is None else None)
    return StructureResult(rows([m.truth for m in doc.matches] + list(doc.missing)),
                           rows([m.map for m in doc.matches] + list(doc.extra)), matching)


def structures_of(doc: s.Structures3D | None) -> Structures3D | None:
    """The block read back (None when the document has none)."""
    if doc is None:
        return None
    return Structures3D({"planes": _result_of("planes", doc.planes),
                         "plane_lines": _result_of("plane_lines", doc.plane_lines)},
                        doc.planes.max_angle_deg, doc.planes.max_offset_m, _fit_of(doc.fit))
