"""A result's findings (:class:`~pcmapq.results.blocks.Findings`) as its JSON document
(:class:`~pcmapq.results.schema.ResultDocument`) and back. Writing and reading go through the
one schema; what the document does not hold reads back absent (rasters None, feature strengths
and pair costs NaN)."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pcmapq import __version__
from pcmapq.core.frames import Frames
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.features import Features
from pcmapq.features.names import MATCH_THRESHOLD
from pcmapq.match import Matching
from pcmapq.metrics.distances import Distances
from pcmapq.metrics.map_gaussians import MapGaussians
from pcmapq.results import schema as s
from pcmapq.results.blocks import DetectorResult, Findings, Overlap
from pcmapq.results.blocks3d import consistency_3d_block, consistency_3d_of
from pcmapq.results.structures_doc import structures_block, structures_of

if TYPE_CHECKING:
    from pcmapq.align.regions import Consistency

#: The columns of a region, in the JSON and the regions CSV.
REGION_COLUMNS = tuple(s.Region.model_fields)


def document(r: Findings, features: bool = True) -> s.ResultDocument:
    """The result's document; ``features=False``: its figures alone, with the lists of
    matched, missing and extra features left empty."""
    tf = r.transform
    x0, y0, yaw0 = r.grid.origin
    a, o = r.alignment, r.overlap
    optional: dict[str, Any] = {}
    if r.registration_3d is not None:
        reg = r.registration_3d
        optional["alignment_3d"] = s.Registration3D(matrix=reg.transform.tolist(),
                                                    fitness=reg.fitness, rmse_m=reg.rmse_m)
        optional["distances_3d"] = _distances(r.distances_3d)
    if r.map_3d is not None:
        g = r.map_3d
        optional["map_3d"] = s.Map3D(computed_on=g.basis, voxels=g.voxels, awd_m=g.awd_m,
                                     scs=g.scs)
    if r.consistency_3d is not None:
        optional["consistency_3d"] = consistency_3d_block(r.consistency_3d)
    if r.structures is not None:
        optional["structures_3d"] = structures_block(r.structures, features)
    if r.rooms is not None:
        optional["rooms"] = r.rooms
    rows = _feature_rows(r) if features else ([], [], [])
    return s.ResultDocument(
        pcmapq=s.Producer(version=__version__, command=r.command),
        settings=r.settings,
        map=s.MapInput(path=str(r.map_path), kind=r.map_kind, **(r.map_message or {})),
        truth=s.TruthInput(path=str(r.truth_path), kind=r.truth_kind,
                           resolution_m=r.grid.resolution,
                           origin=s.Origin(x_m=x0, y_m=y0, yaw_deg=float(np.degrees(yaw0))),
                           shape=r.grid.shape,
                           **({} if r.truth_sha256 is None else {"sha256": r.truth_sha256})),
        alignment=s.Alignment(
            **tf.to_dict(), matrix=tf.matrix.tolist(), fitness=a.fitness, rmse_m=a.rmse_m,
            tolerance_m=a.tolerance_m, method=a.method, truth_recall=o.truth_recall,
            seen_through=o.seen_through, agreement=o.agreement,
            distinctiveness=a.distinctiveness, contradiction=a.contradiction,
            free_on_truth=a.free_on_truth,
            poses=[s.ScoredPose(**p.to_dict(), score=score) for p, score in a.poses],
            confidence=o.confidence, verdict=o.verdict,
            parts=[s.PartPlaced(**{**asdict(p), "pose": p.pose.to_dict()}) for p in o.parts]),
        consistency=consistency_block(r.consistency),
        frames=s.Frames.model_validate(r.frames.to_dict()),
        coverage=o.coverage, footprint=r.footprint_rule,
        scored_against="whole truth" if r.full else "footprint",
        distances=_distances(r.distances), noref=None,
        detectors={name: _detector(r, name, det) for name, det in r.detectors.items()},
        matches=rows[0], missing=rows[1], extra=rows[2], **optional)


def fields(doc: s.ResultDocument) -> dict[str, Any]:
    """The keyword arguments of the result (its :class:`Findings`) a document holds."""
    from pcmapq.align import Alignment  # runtime imports: reading a 3D result loads Open3D
    from pcmapq.align.parts import Part
    from pcmapq.align.rigid3d import Registration3D

    a, t = doc.alignment, doc.truth
    frames = Frames.from_dict(doc.frames.model_dump())
    reg = doc.alignment_3d
    parts = tuple(Part(**{**p.model_dump(exclude={"pose"}),
                          "pose": Similarity2D.from_dict(p.pose.model_dump())})
                  for p in a.parts)
    message = doc.map.model_dump(exclude={"path", "kind"}, exclude_unset=True)
    return dict(
        map_path=Path(doc.map.path), map_kind=doc.map.kind,
        truth_path=Path(t.path), truth_kind=t.kind,
        grid=MetricGrid(t.resolution_m, (t.origin.x_m, t.origin.y_m,
                                         float(np.radians(t.origin.yaw_deg))), t.shape),
        alignment=Alignment(frames.planar, a.fitness, a.rmse_m, a.tolerance_m, a.method,
                            a.distinctiveness, a.contradiction, a.free_on_truth,
                            tuple((Similarity2D.from_dict(q.model_dump()), q.score)
                                  for q in a.poses)),
        overlap=Overlap(None, doc.coverage, a.truth_recall, a.agreement, a.confidence,
                        a.verdict, parts, a.seen_through),
        distances=_distances_of(doc.distances),
        registration_3d=None if reg is None else Registration3D(
            np.asarray(reg.matrix, dtype=np.float64), reg.fitness, reg.rmse_m),
        distances_3d=None if doc.distances_3d is None else _distances_of(doc.distances_3d),
        threshold=_threshold(doc), full=doc.scored_against == "whole truth",
        detectors={name: _detector_of(doc, name) for name in doc.detectors},
        truth_occupied=None, map_occupied=None, frames=frames,
        footprint_rule=doc.footprint, settings=doc.settings, command=doc.pcmapq.command,
        noref=doc.noref, truth_sha256=t.sha256, map_message=message or None,
        consistency=_consistency_of(doc.consistency, a.tolerance_m), rooms=doc.rooms,
        map_3d=None if doc.map_3d is None else MapGaussians(
            doc.map_3d.awd_m, doc.map_3d.scs, doc.map_3d.voxels, doc.map_3d.computed_on),
        consistency_3d=consistency_3d_of(doc.consistency_3d),
        structures=structures_of(doc.structures_3d))


def consistency_block(c: Consistency | None) -> s.ConsistencyMap:
    """The consistency map's block: the tile, the largest held offset and where, the map's
    fitness at its pose and with each region aligned on its own, and the regions."""
    if c is None:
        return s.ConsistencyMap(tile_m=None, largest_offset_m=None, largest_at_m=None,
                                global_fitness=None, local_fitness=None, regions=[])
    k = c.largest()
    regions = [s.Region(**dict(zip(REGION_COLUMNS, row, strict=True))) for row in zip(
        c.centre[:, 0].tolist(), c.centre[:, 1].tolist(), c.offset[:, 0].tolist(),
        c.offset[:, 1].tolist(), c.offset_m.tolist(), c.turn_deg.tolist(),
        c.points.astype(int).tolist(), c.fit_before.tolist(), c.fit_after.tolist(),
        c.held.astype(bool).tolist(), strict=True)]
    return s.ConsistencyMap(
        tile_m=c.tile_m, largest_offset_m=None if k is None else float(c.offset_m[k]),
        largest_at_m=None if k is None else tuple(float(v) for v in c.centre[k]),
        global_fitness=c.global_fitness(), local_fitness=c.local_fitness(), regions=regions)


def _distances(d: Distances) -> s.Distances:
    return s.Distances(computed_on=d.basis, accuracy_m=d.accuracy,
                       completeness_m=d.completeness, chamfer_m=d.chamfer_m,
                       f_score=list(d.fscores))


def _distances_of(doc: s.Distances) -> Distances:
    return Distances(doc.accuracy_m, doc.completeness_m, doc.chamfer_m, tuple(doc.f_score),
                     doc.computed_on)


def _detector(r: Findings, name: str, det: DetectorResult) -> s.Detector:
    m = det.matching
    return s.Detector(quality=m.quality, precision=m.precision, f1=m.f1, note=r.note(name),
                      truth_features=m.truth_features, map_features=m.map_features,
                      matched=m.matched, matched_map=m.matched_map, threshold_m=r.threshold,
                      displacement_m=det.displacement_stats())


def _feature_rows(r: Findings) -> tuple[list[s.Match], list[s.Missing], list[s.Extra]]:
    """Every detector's matched pairs, missing truth features and extra map features."""
    matches: list[s.Match] = []
    missing: list[s.Missing] = []
    extra: list[s.Extra] = []
    for name, det in r.detectors.items():
        m = det.matching
        matches += [s.Match(detector=name, truth_xy_m=t, map_xy_m=p, displacement_m=d,
                            counted=s.Counted(truth=ts, map=ms))
                    for t, p, d, ts, ms in zip(
                        det.truth_xy.tolist(), det.map_xy.tolist(), det.distances.tolist(),
                        det.truth.strong[m.truth_idx].tolist(),
                        det.map.strong[m.map_idx].tolist(), strict=True)]
        missing += [s.Missing(detector=name, truth_xy_m=t)
                    for t in det.truth.xy[m.missing].tolist()]
        extra += [s.Extra(detector=name, map_xy_m=p) for p in det.map.xy[m.extra].tolist()]
    return matches, missing, extra


def _xy(points: list[tuple[float, float]]) -> np.ndarray:
    return np.array(points, dtype=np.float64).reshape(-1, 2)


def _detector_of(doc: s.ResultDocument, name: str) -> DetectorResult:
    """One detector read back: the truth's features are the matched ones then the missing
    ones, the map's the matched ones then the extra ones."""
    d = doc.detectors[name]
    matches = [m for m in doc.matches if m.detector == name]
    missing = [m.truth_xy_m for m in doc.missing if m.detector == name]
    extra = [m.map_xy_m for m in doc.extra if m.detector == name]
    n, k, e = len(matches), len(missing), len(extra)
    t_strong = np.array([m.counted.truth for m in matches] + [True] * k, dtype=bool)
    m_strong = np.array([m.counted.map for m in matches] + [True] * e, dtype=bool)
    truth_xy = np.vstack([_xy([m.truth_xy_m for m in matches]), _xy(missing)])
    map_xy = np.vstack([_xy([m.map_xy_m for m in matches]), _xy(extra)])
    pairs = np.arange(n)
    # A detector's saved note stands when none of its scores is defined (it may have had
    # nothing to find, which its counts alone do not tell); otherwise it follows from them.
    unscored = d.note if d.quality is None and d.precision is None else None
    matching = Matching(
        truth_idx=pairs, map_idx=pairs, displacement=map_xy[:n] - truth_xy[:n],
        cost=np.full(n, np.nan), quality=d.quality, precision=d.precision, f1=d.f1,
        truth_features=d.truth_features, map_features=d.map_features, matched=d.matched,
        matched_map=d.matched_map, missing=np.arange(n, n + k), extra=np.arange(n, n + e),
        unscored=unscored)
    return DetectorResult(Features(truth_xy, np.full(n + k, np.nan), t_strong),
                          Features(map_xy, np.full(n + e, np.nan), m_strong), matching)


def _threshold(doc: s.ResultDocument) -> float:
    """The matching threshold: the detectors', else the settings' (metres)."""
    for d in doc.detectors.values():
        return d.threshold_m
    matching = (doc.settings or {}).get("matching") or {}
    return matching.get("threshold", MATCH_THRESHOLD)


def _consistency_of(doc: s.ConsistencyMap | None, tolerance: float) -> Consistency | None:
    """The consistency map read back (None when there was none)."""
    from pcmapq.align.regions import Consistency

    if doc is None or doc.tile_m is None:
        return None
    rows = doc.regions

    def column(key: str, dtype=np.float64) -> np.ndarray:
        return np.array([getattr(r, key) for r in rows], dtype=dtype)

    return Consistency(doc.tile_m, tolerance,
                       np.column_stack([column("x_m"), column("y_m")]).reshape(-1, 2),
                       np.column_stack([column("dx_m"), column("dy_m")]).reshape(-1, 2),
                       column("turn_deg"), column("points", int), column("fitness_before"),
                       column("fitness_after"), column("held", bool))
