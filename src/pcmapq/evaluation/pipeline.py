"""evaluate(): the method in one screen. load -> align -> raster -> features -> match -> score."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pcmapq.align import Alignment
from pcmapq.align.parts import broken_off, place_parts
from pcmapq.align.planar import RigidTarget
from pcmapq.align.regions import regions
from pcmapq.align.rigid3d import Registration3D
from pcmapq.core import memory
from pcmapq.core.bounds import bounds
from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.core.frames import Frames, Levelling
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.inputs import (
    MAP_CROP,
    TRUTH_CROP,
    load_pair,
    min_hits,
    plan_points,
    truth_cells,
    truth_grid,
)
from pcmapq.evaluation.noref_figures import input_figures
from pcmapq.evaluation.placing import align_clouds_3d, align_plan
from pcmapq.evaluation.same_place import overlap, refusal, verdict
from pcmapq.features import Features, SideBySide, default_params
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.digest import sha256_file
from pcmapq.io.extent import check_span, hint
from pcmapq.match import match
from pcmapq.metrics.distances import distances, distances_3d, nearest_distance
from pcmapq.raster.draw import OCCUPIED, UNKNOWN, points_to_grid, warp_state
from pcmapq.raster.footprint import footprint_rule, map_footprint
from pcmapq.raster.seen import seen_on
from pcmapq.results.result import OTHER, DetectorResult, Overlap, Result
from pcmapq.settings import Settings

Progress = Callable[[str], None]

def map_footprint_rule(source: OccupancyMap | PointMap, settings: Settings) -> str:
    """The footprint rule this map follows: ``settings.footprint.rule`` with ``auto`` resolved (see
    :func:`pcmapq.raster.footprint.footprint_rule`); a rule the map cannot follow is bad input."""
    image = isinstance(source, OccupancyMap)
    try:
        return footprint_rule(settings.footprint.rule, source.state == UNKNOWN if image else None,
                              source.grid.resolution if image else 0.0,
                              views=not image and source.seen is not None)
    except ValueError as err:
        raise InputError(f"{source.path}: {err}") from None


def map_raster(source: OccupancyMap | PointMap, map_xy: np.ndarray, transform: Similarity2D,
               grid: MetricGrid, settings: Settings,
               rule: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The aligned map drawn into the truth's grid: its occupied cells and its footprint (the
    area it observed under ``rule``, by default :func:`map_footprint_rule`'s, see
    :mod:`pcmapq.raster.footprint`), both bool."""
    image = isinstance(source, OccupancyMap)
    rule = map_footprint_rule(source, settings) if rule is None else rule
    seen = None
    if image:
        state = warp_state(source.state, source.grid, transform, grid)
        occupied, known = state == OCCUPIED, state != UNKNOWN
        rows, cols = source.grid.shape
        corners = source.grid.pixels_to_xy(
            np.array([[-0.5, -0.5], [cols - 0.5, -0.5], [cols - 0.5, rows - 0.5],
                      [-0.5, rows - 0.5]]))
    else:
        occupied = points_to_grid(transform.apply(map_xy), grid, min_hits(source, settings))
        known = None
        if rule == "seen" and source.seen is not None:
            seen = seen_on(source.seen, transform, grid)
        (x0, y0), (x1, y1) = bounds(map_xy)
        corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    footprint = map_footprint(rule, occupied, grid, settings.footprint.margin, known=known,
                              rectangle=transform.apply(corners), seen=seen)
    return occupied, footprint


def inside(features: Features, area: np.ndarray, grid: MetricGrid) -> np.ndarray:
    """(N,) bool: which features lie in the cells where ``area`` is true."""
    uv = np.floor(grid.xy_to_pixels(features.xy) + 0.5).astype(int)
    rows, cols = area.shape
    ok = (uv[:, 0] >= 0) & (uv[:, 0] < cols) & (uv[:, 1] >= 0) & (uv[:, 1] < rows)
    return ok & area[np.clip(uv[:, 1], 0, rows - 1), np.clip(uv[:, 0], 0, cols - 1)]


def evaluate(map_path: str | Path | PointMap, truth_path: str | Path,
             settings: Settings | None = None, progress: Progress = lambda step: None,
             memory_limit: int | None = None, truth_sha256: str | None = None) -> Result:
    """Score the map at ``map_path`` (or a map already built, e.g. from scans) against the
    truth at ``truth_path``; stop (InputError) when the run would need more than
    ``memory_limit`` bytes (None: :func:`pcmapq.core.memory.default_limit`).
    ``truth_sha256``: the truth file's SHA-256 when the caller has it (a batch row's key),
    else read here."""
    settings = Settings() if settings is None else settings
    progress("loading")
    source, truth = load_pair(map_path, truth_path, settings, memory_limit)
    result = score(source, truth, settings, progress, memory_limit)
    return replace(result, truth_sha256=truth_sha256 or sha256_file(truth_path))


def needed_memory(inputs: Sequence[OccupancyMap | PointMap], grid: MetricGrid,
                  more_maps: int = 0) -> int:
    """Estimated peak memory, bytes, of scoring a map against a truth (``inputs``: both, or
    the truth alone for what it needs whatever the map) on the truth's ``grid``, with
    ``more_maps`` maps more scored on it at once: see :mod:`pcmapq.core.memory`."""
    images = sum(int(np.prod(s.grid.shape)) for s in inputs if isinstance(s, OccupancyMap))
    points = sum(len(s.points) for s in inputs if isinstance(s, PointMap))
    cells = int(np.prod(grid.shape))
    extent = cells * grid.resolution**2
    one_map = memory.needed_bytes(0, cells, extent, 0) - memory.BASE
    return memory.needed_bytes(images, cells, extent, points) + more_maps * one_map


def harris_corners(truth: OccupancyMap | PointMap, found: dict[str, Features],
                   settings: Settings) -> int | None:
    """The strong Harris corners an image truth's no-reference figures count, taken from the
    features the method found on it when it ran Harris with the default parameters (the same
    detection on the same cells); None otherwise."""
    if not isinstance(truth, OccupancyMap) or "harris" not in found or \
            settings.matching.params.get("harris") != default_params()["harris"]:
        return None
    return int(np.count_nonzero(found["harris"].strong))


@dataclass(frozen=True)
class PreparedTruth:
    """The truth as every score against it needs it, whatever the map: its plan points ``xy``
    (N, 2) metres with the ``level`` that made them, the ``grid`` everything is drawn on, its
    ``occupied`` cells, its ``features`` by detector and, when computed, ``to_truth``: each
    cell's distance to the nearest truth wall, metres; ``aligner``: its points prepared for
    the rigid alignment (:class:`~pcmapq.align.planar.RigidTarget`); ``maps``: how many maps
    may be scored on its grid at once in the memory allowed. Made once by
    :func:`pcmapq.evaluation.prepared.prepare_truth` for many maps (``pcmapq track``'s steps)."""

    source: OccupancyMap | PointMap
    xy: np.ndarray
    level: Levelling | None
    grid: MetricGrid
    occupied: np.ndarray
    features: dict[str, Features]
    to_truth: np.ndarray | None = None
    aligner: RigidTarget | None = None
    maps: int = 1


def _band_words(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
                settings: Settings) -> str:
    """How a 3D cloud's cells were made, for the wall distances' basis; '' when neither input
    is a 3D cloud."""
    if not any(isinstance(s, PointMap) and s.is_3d for s in (source, truth)):
        return ""
    r = settings.raster
    return f" (a 3D cloud: its wall band, {r.band_low:g} to {r.band_high:g} m above its floor)"


@dataclass(frozen=True)
class MapSide:
    """One map aligned and drawn on the truth's grid: ``source`` (in the truth frame after a
    3D registration), its plan points ``xy`` (N, 2) metres in its own plan frame, the
    alignment, its ``occupied`` cells, ``to_map`` (each cell's distance to them, metres), the
    overlap, its features by detector and ``target``: the truth's points as its alignment
    used them."""

    source: OccupancyMap | PointMap
    registration: Registration3D | None
    xy: np.ndarray
    level: Levelling | None
    alignment: Alignment
    occupied: np.ndarray
    to_map: np.ndarray
    cover: Overlap
    features: dict[str, Features]
    target: RigidTarget | None = None


def place_map(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
              truth_xy: np.ndarray, grid: MetricGrid, truth_occ: np.ndarray,
              settings: Settings, rule: str, progress: Progress = lambda step: None,
              target: RigidTarget | None = None) -> MapSide:
    """Align ``source`` to the truth (plan points ``truth_xy``, metres; ``target``: them
    prepared for the rigid alignment), draw it on ``grid`` and measure the overlap with
    ``truth_occ``: a :class:`MapSide` without features. A map that does not seem to show the
    truth's place is refused (EvaluationError) unless ``--force``."""
    progress("aligning")
    option = settings.alignment
    source, registration = align_clouds_3d(source, truth, settings)
    map_xy, map_level = plan_points(source, settings)
    if target is None or not target.fits(option.params):
        target = RigidTarget(truth_xy, option.params)
    alignment = align_plan(source, map_xy, truth_xy, registration, settings, target)

    progress("rasterising")
    map_occ, footprint = map_raster(source, map_xy, alignment.transform, grid, settings, rule)
    to_map = nearest_distance(map_occ, grid)
    cover = overlap(truth_occ, to_map, footprint, alignment, grid.resolution)
    parts = ()
    if cover.confidence < option.min_confidence and alignment.distinctiveness is not None:
        progress("placing the map's parts on their own")
        parts = tuple(place_parts(map_xy, truth_xy, alignment.transform, option.params, target))
    cover = replace(cover, parts=parts,
                    verdict=verdict(cover.confidence, option.min_confidence, parts))
    if cover.verdict == OTHER and not option.force:
        raise EvaluationError(refusal(source, truth.path, alignment, cover, settings, map_xy,
                                      truth_xy))
    return MapSide(source, registration, map_xy, map_level, alignment, map_occ, to_map, cover,
                   {}, target)


def with_features(side: MapSide, grid: MetricGrid, sides: SideBySide,
                  progress: Progress = lambda step: None, threads: int = 2) -> MapSide:
    """``side`` with its features by detector, found with ``sides`` on ``threads`` threads."""
    progress("drawing the walls' centre lines and detecting features")
    return replace(side, features=sides.features(side.occupied, grid, threads=threads))


def map_side(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
             truth_xy: np.ndarray, grid: MetricGrid, truth_occ: np.ndarray, settings: Settings,
             sides: SideBySide, rule: str, progress: Progress = lambda step: None,
             threads: int = 2) -> MapSide:
    """:func:`place_map`, then :func:`with_features` with ``sides`` on ``threads`` threads."""
    side = place_map(source, truth, truth_xy, grid, truth_occ, settings, rule, progress)
    return with_features(side, grid, sides, progress, threads)


def score(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap, settings: Settings,
          progress: Progress = lambda step: None, memory_limit: int | None = None) -> Result:
    """Score a loaded map against a loaded truth: align, raster, detect, match; stop first
    (InputError) when that would need more than ``memory_limit`` bytes (None: the default).
    The truth's features do not depend on the map: they are found on a second thread while
    the map is aligned and drawn (see :class:`~pcmapq.features.SideBySide`)."""
    check_span(truth, TRUTH_CROP)
    check_span(source, MAP_CROP)
    rule = map_footprint_rule(source, settings)
    truth_xy, truth_level = plan_points(truth, settings)
    grid = truth_grid(truth, truth_xy, settings)
    memory.guard(needed_memory((source, truth), grid), memory_limit,
                 f"{source.path} against {truth.path}",
                 lambda: hint(truth, TRUTH_CROP, grid.resolution) or hint(source, MAP_CROP))
    truth_occ = truth_cells(truth, truth_xy, grid, settings)
    sides = SideBySide(settings.matching.detectors, settings.matching.params)
    with ThreadPoolExecutor(1) as background:
        truth_side = background.submit(sides.features, truth_occ, grid)
        try:
            side = map_side(source, truth, truth_xy, grid, truth_occ, settings, sides, rule,
                            progress)
            prepared = PreparedTruth(truth, truth_xy, truth_level, grid, truth_occ,
                                     truth_side.result())
        except BaseException:
            sides.cancel()
            raise
    return assemble(source, side, prepared, settings, rule, progress)


def assemble(loaded: OccupancyMap | PointMap, side: MapSide, prepared: PreparedTruth,
             settings: Settings, rule: str, progress: Progress = lambda step: None) -> Result:
    """The result of the map ``loaded`` (as given, before any 3D registration), aligned and
    drawn as ``side``, against ``prepared``: matches inside the footprint, wall distances, the
    optional no-reference and 3D figures."""
    truth, grid, alignment = prepared.source, prepared.grid, side.alignment
    registration, footprint = side.registration, side.cover.footprint
    frames = Frames(alignment.transform, side.level, prepared.level,
                    None if registration is None else registration.transform)
    detectors = {}
    full, threshold = settings.footprint.full, settings.matching.threshold
    for name in settings.matching.detectors:
        truth_f, map_f = prepared.features[name], side.features[name]
        if not full:  # truth features the map never saw are not missing
            truth_f = truth_f.counted_where(inside(truth_f, footprint, grid))
            if rule == "seen":  # nor are the features of walls its scans only dotted extra
                map_f = map_f.counted_where(inside(map_f, footprint, grid))
        detectors[name] = DetectorResult(truth_f, map_f,
                                         match(name, truth_f, map_f, threshold,
                                               settings.matching.params.get(name)))
    consistency = None
    if side.cover.verdict != OTHER and side.target is not None and side.target.lines is not None:
        progress("aligning the map's regions on their own")
        consistency = regions(side.xy, alignment.transform, side.target.lines,
                              alignment.tolerance_m,
                              starts=broken_off(side.cover.parts, side.xy, alignment.transform))
    noref = None
    if settings.noref.enabled:
        progress("no-reference figures")
        scale = alignment.transform.scale if settings.alignment.scale else 1.0
        corners = harris_corners(truth, prepared.features, settings)
        noref = {"map": input_figures(loaded, settings.noref, scale=scale),
                 "truth": input_figures(truth, settings.noref, corners=corners)}
    cloud_distances = None
    if registration is not None:
        progress("distances in 3D")
        cloud_distances = distances_3d(side.source.points, truth.points,
                                       settings.raster.cloud_resolution, settings.distances.taus)
    return Result(map_path=Path(loaded.path), map_kind=side.source.kind,
                  truth_path=Path(truth.path), truth_kind=truth.kind, grid=grid,
                  alignment=alignment, overlap=side.cover,
                  distances=distances(prepared.occupied, side.occupied, footprint, grid,
                                      settings.distances.taus, side.to_map, prepared.to_truth,
                                      _band_words(side.source, truth, settings)),
                  registration_3d=registration, distances_3d=cloud_distances,
                  threshold=threshold, full=full, detectors=detectors,
                  footprint_rule=rule, frames=frames, settings=settings.to_dict(),
                  truth_occupied=prepared.occupied, map_occupied=side.occupied, noref=noref,
                  consistency=consistency)
