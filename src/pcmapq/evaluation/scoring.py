"""A placed map scored against its prepared truth (:func:`score`): features matched one to one
inside the footprint, wall distances, the consistency map of its regions (and of two 3D
clouds, its 3D one), and the optional no-reference and 3D figures (two 3D clouds' distances,
AWD and SCS, and structures), gathered in a
:class:`~pcmapq.results.result.Result`."""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

from pcmapq.align.parts import broken_off
from pcmapq.align.refine3d import last_reach
from pcmapq.align.regions import regions
from pcmapq.align.regions3d import regions_3d
from pcmapq.core.frames import Frames
from pcmapq.core.grid import MetricGrid
from pcmapq.evaluation.noref_figures import EarlyFigures, input_figures
from pcmapq.evaluation.placing import Placed, Progress
from pcmapq.evaluation.truth import FEATURE_THREADS, PlanesOnce, PreparedTruth, plane_params
from pcmapq.features import Features, SideBySide, default_params
from pcmapq.features.planes3d import Planes
from pcmapq.features.rooms import Params as RoomParams
from pcmapq.features.rooms import drawn, share_inside
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.match import match
from pcmapq.match.rooms import room_table
from pcmapq.match.structures import Structures3D, compare_structures
from pcmapq.metrics.distances import distances, distances_3d
from pcmapq.metrics.map_gaussians import map_gaussians
from pcmapq.results.result import OTHER, DetectorResult, Result
from pcmapq.settings import Settings, StructuresConfig


def score(placed: Placed, prepared: PreparedTruth, settings: Settings,
          progress: Progress = lambda step: None, early: EarlyFigures | None = None) -> Result:
    """The result of a map placed on the prepared truth: its features (found here unless
    ``placed`` has them) matched one to one against the truth's inside the footprint, the wall
    distances, the consistency map, the optional no-reference and 3D figures (those ``early``
    found while the map was placed taken from it)."""
    side, loaded, rule = placed, placed.given, placed.rule
    truth, grid, alignment = prepared.source, prepared.grid, side.alignment
    registration, footprint = side.registration, side.cover.footprint
    with ThreadPoolExecutor(3, thread_name_prefix="pcmapq-score") as pool:
        # the consistency map and the 3D distances need only the placed map: found while the
        # map's features are
        consistency_job = cloud_job = gaussians_job = consistency_3d_job = None
        if side.cover.verdict != OTHER and side.target is not None and \
                side.target.lines is not None:
            progress("aligning the map's regions on their own")
            consistency_job = pool.submit(
                regions, side.xy, alignment.transform, side.target.lines,
                alignment.tolerance_m,
                starts=broken_off(side.cover.parts, side.xy, alignment.transform))
        if registration is not None:
            progress("distances in 3D")
            cloud_job = pool.submit(distances_3d, side.source.points, truth.points,
                                    settings.raster.cloud_resolution, settings.distances.taus)
            progress("registering the map's regions in 3D on their own")
            consistency_3d_job = pool.submit(
                regions_3d, side.source.points, truth.points, tile_m=settings.map_3d.tile,
                voxel=settings.alignment.voxel_3d,
                level=None if prepared.level is None else prepared.level.rotation,
                scan=side.source.scan, stretch=settings.map_3d.stretch)
        if in_one_frame_3d(side, truth, settings):
            m3 = settings.map_3d
            gaussians_job = pool.submit(map_gaussians, side.source.points, truth.points,
                                        m3.voxel, m3.min_points, m3.radius)
        structures_job = None
        if registration is not None and settings.structures.enabled:
            progress("3D structures")
            structures_job = pool.submit(structures_3d, truth.points, side.source.points,
                                         settings.structures,
                                         last_reach(settings.alignment.voxel_3d),
                                         prepared.planes)
        if placed.features is None:
            progress("drawing the walls' centre lines and detecting features")
            sides = prepared.sides or SideBySide(settings.matching.detectors,
                                                 settings.matching.params)
            side = replace(placed, features=sides.features(placed.occupied, prepared.grid,
                                                           threads=FEATURE_THREADS))
        if early is not None:  # this thread is free until the jobs end: a side's
            early.help()  # no-reference figures their thread has not started, found here
        consistency = None if consistency_job is None else consistency_job.result()
        cloud_distances = None if cloud_job is None else cloud_job.result()
        gaussians = None if gaussians_job is None else gaussians_job.result()
        consistency_3d = None if consistency_3d_job is None else consistency_3d_job.result()
        structures = None if structures_job is None else structures_job.result()
    frames = Frames(alignment.transform, side.level, prepared.level,
                    None if registration is None else registration.transform)
    detectors = {}
    full, threshold = settings.footprint.full, settings.matching.threshold
    for name in settings.matching.detectors:
        truth_f, map_f = prepared.features[name], side.features[name]
        params = settings.matching.params.get(name)
        if not full:  # truth features the map never saw are not missing
            truth_f = truth_f.counted_where(inside(truth_f, footprint, grid, params, map_f))
            if rule == "seen":  # nor are the features of walls its scans only dotted extra
                map_f = map_f.counted_where(inside(map_f, footprint, grid, params))
        detectors[name] = DetectorResult(truth_f, map_f,
                                         match(name, truth_f, map_f, threshold, params))
    rooms = None if "rooms" not in detectors else \
        room_table(detectors["rooms"].truth, detectors["rooms"].map)
    noref = None
    if settings.noref.enabled:
        progress("no-reference figures")
        scale = alignment.transform.scale if settings.alignment.scale else 1.0
        corners = harris_corners(truth, prepared.features, settings)
        found = {} if early is None else {name: early.get(name) for name in ("map", "truth")}
        noref = {"map": found.get("map") or input_figures(loaded, settings.noref, scale=scale),
                 "truth": found.get("truth") or input_figures(truth, settings.noref,
                                                              corners=corners)}
    return Result(map_path=Path(loaded.path), map_kind=side.source.kind,
                  truth_path=Path(truth.path), truth_kind=truth.kind, grid=grid,
                  alignment=alignment, overlap=side.cover,
                  distances=distances(prepared.occupied, side.occupied, footprint, grid,
                                      settings.distances.taus, side.to_map, prepared.to_truth,
                                      _band_words(side.source, truth, settings)),
                  registration_3d=registration, distances_3d=cloud_distances,
                  threshold=threshold, full=full, detectors=detectors,
                  footprint_rule=rule, frames=frames,
                  settings=recorded_settings(
                      settings, gaussians is not None or consistency_3d is not None,
                      registration is not None),
                  truth_occupied=prepared.occupied, map_occupied=side.occupied, noref=noref,
                  consistency=consistency, rooms=rooms, map_3d=gaussians,
                  consistency_3d=consistency_3d, structures=structures,
                  map_message=None if getattr(loaded, "message", None) is None
                  else loaded.message.to_dict())


def in_one_frame_3d(placed: Placed, truth: OccupancyMap | PointMap, settings: Settings) -> bool:
    """Whether the map and the truth are two 3D clouds in one frame: registered in 3D, or in
    the frame the map was given in (``--no-align``). MapEval's map figures need them so."""
    both_3d = all(isinstance(c, PointMap) and c.is_3d for c in (placed.source, truth))
    return both_3d and (placed.registration is not None or not settings.alignment.enabled)


def recorded_settings(settings: Settings, map_3d: bool, structures: bool) -> dict:
    """The settings a result records (:meth:`Settings.to_dict`), the ``map_3d`` group only
    when the result has the figures it sets (AWD and SCS, the 3D consistency map), the
    ``structures`` group only for two 3D clouds registered in 3D (where ``--no-structures``
    is a choice worth recording): a 2D result records neither."""
    kept = {"map_3d": map_3d, "structures": structures}
    return {k: v for k, v in settings.to_dict().items() if kept.get(k, True)}


def structures_3d(truth: np.ndarray, map_: np.ndarray, option: StructuresConfig,
                  reach: float | None = None,
                  truth_planes: Future[Planes] | PlanesOnce | None = None) -> Structures3D:
    """The 3D structures of two clouds (N, 3), both in the truth frame, metres, found and
    matched with ``option`` (:func:`~pcmapq.match.structures.compare_structures`), the map's
    moved by the planes' own fit when it moves none more than ``reach`` metres (the 3D
    registration's last ICP correspondence distance; None: whatever it moves).
    ``truth_planes``: the job finding the truth's planes with ``option``, or the planes found
    once for every map (:class:`~pcmapq.evaluation.truth.PlanesOnce`; None: found here);
    a job that has not started (its thread still on the truth's features) is cancelled and the
    planes found here, beside the map's, rather than waited for."""
    early = None
    if truth_planes is not None and not truth_planes.cancel():  # running or done
        early = truth_planes.result()
    return compare_structures(truth, map_, plane_params(option), option.line_margin,
                              option.line_length, option.max_angle, option.max_offset, reach, early)


def inside(features: Features, area: np.ndarray, grid: MetricGrid,
           params: object = None, other: Features | None = None) -> np.ndarray:
    """(N,) bool: which features lie in the cells where ``area`` is true; rooms (features
    with cells), those with at least ``min_seen`` of their cells there, or at least
    ``min_drawn`` where ``other`` (the other side's rooms) drew a room over them (their
    ``params``, or the rooms' defaults; see :class:`~pcmapq.features.rooms.Params`)."""
    if features.labels is not None:
        p = params if isinstance(params, RoomParams) else RoomParams()
        share = share_inside(features, area, grid)
        seen = share >= p.min_seen
        maybe = (share >= p.min_drawn) & ~seen  # only these can count by the map's rooms
        if other is not None and maybe.any():
            seen |= maybe & drawn(features, other)
        return seen
    uv = np.floor(grid.xy_to_pixels(features.xy) + 0.5).astype(int)
    rows, cols = area.shape
    ok = (uv[:, 0] >= 0) & (uv[:, 0] < cols) & (uv[:, 1] >= 0) & (uv[:, 1] < rows)
    return ok & area[np.clip(uv[:, 1], 0, rows - 1), np.clip(uv[:, 0], 0, cols - 1)]


def harris_corners(truth: OccupancyMap | PointMap, found: dict[str, Features],
                   settings: Settings) -> int | None:
    """The strong Harris corners an image truth's no-reference figures count, taken from the
    features the method found on it when it ran Harris with the default parameters (the same
    detection on the same cells); None otherwise."""
    if not isinstance(truth, OccupancyMap) or "harris" not in found or \
            settings.matching.params.get("harris") != default_params()["harris"]:
        return None
    return int(np.count_nonzero(found["harris"].strong))


def _band_words(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
                settings: Settings) -> str:
    """How a 3D cloud's cells were made, for the wall distances' basis; '' when neither input
    is a 3D cloud."""
    if not any(isinstance(s, PointMap) and s.is_3d for s in (source, truth)):
        return ""
    r = settings.raster
    return f" (a 3D cloud: its wall band, {r.band_low:g} to {r.band_high:g} m above its floor)"
