"""A map placed on a prepared truth (:func:`place`): two 3D clouds registered in 3D, then the
2D alignment of the plans (the global search and ICP of :func:`pcmapq.align.align`, or the
plan as it is after a 3D registration), the map drawn on the truth's grid with its footprint,
and the verdict whether it shows the truth's place at all (a map of another place is refused
unless ``--force``). The check, before the search, that the map's size can be the truth's."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from pcmapq.align import Alignment, align
from pcmapq.align.free_space import FreeSpace
from pcmapq.align.parts import place_parts
from pcmapq.align.plan_guess import guess_from_plans
from pcmapq.align.planar import RigidTarget
from pcmapq.align.rigid3d import Registration3D, align_3d, apply
from pcmapq.align.stretches import run_stretches
from pcmapq.core.bounds import bounds, radius
from pcmapq.core.errors import EvaluationError, InputError, Refused, SettingsRefused
from pcmapq.core.frames import Levelling
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.inputs import MAP_CROP, TRUTH_CROP, min_hits, plan_points, registered_in_3d
from pcmapq.evaluation.same_place import OVERSIZE, overlap, refusal, verdict
from pcmapq.evaluation.truth import PreparedTruth
from pcmapq.features import Features
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.clouds import SEEN_CELL
from pcmapq.io.extent import check_span, hint
from pcmapq.metrics.distances import DistanceField, nearest_distance
from pcmapq.raster.draw import FREE, OCCUPIED, UNKNOWN, points_to_grid, warp_state
from pcmapq.raster.footprint import check_rule, footprint_rule, map_footprint
from pcmapq.raster.seen import seen_on
from pcmapq.results.result import OTHER, Overlap
from pcmapq.settings import Settings

Progress = Callable[[str], None]


@dataclass(frozen=True)
class Placed:
    """One map placed on a prepared truth: ``given`` (the map as loaded), ``source`` (in the
    truth frame after a 3D registration), its plan points ``xy`` (N, 2) metres in its own plan
    frame, the alignment, its ``occupied`` cells on the truth's grid, ``to_map`` (each cell's
    distance to them, metres), the overlap, the footprint ``rule`` it followed and ``target``:
    the truth's points as its alignment used them. ``features``: its features by detector,
    once :func:`pcmapq.evaluation.scoring.score` has found them."""

    given: OccupancyMap | PointMap
    source: OccupancyMap | PointMap
    registration: Registration3D | None
    xy: np.ndarray
    level: Levelling | None
    alignment: Alignment
    occupied: np.ndarray
    to_map: DistanceField
    cover: Overlap
    rule: str
    target: RigidTarget | None = None
    features: dict[str, Features] | None = None


def place(source: OccupancyMap | PointMap, prepared: PreparedTruth, settings: Settings,
          progress: Progress = lambda step: None,
          walls_found: Callable[[], None] = lambda: None) -> Placed:
    """Align ``source`` to the prepared truth, draw it on the truth's grid and measure the
    overlap. A map that does not seem to show the truth's place is refused (EvaluationError)
    unless ``settings.alignment.force``. ``walls_found`` is called once the map's plan points
    are found (a cloud's wall band, the first large step)."""
    check_span(source, MAP_CROP)
    check_init_3d(source, prepared.source, settings)
    rule = map_footprint_rule(source, settings)
    progress("aligning")
    option, truth = settings.alignment, prepared.source
    given = source
    target = prepared.aligner
    if target is None or not target.fits(option.params):
        target = RigidTarget(prepared.xy, option.params)
    source, registration = align_clouds_3d(source, truth, settings, (prepared, target))
    map_xy, map_level = plan_points(source, settings)
    walls_found()
    alignment = align_plan(source, map_xy, prepared.xy, registration, settings, target,
                           free_space(source, prepared))

    progress("rasterising")
    map_occ, footprint = map_raster(source, map_xy, alignment.transform, prepared.grid,
                                    settings, rule)
    to_map = nearest_distance(map_occ, prepared.grid)
    cover = overlap(prepared.occupied, to_map, footprint, alignment, prepared.grid.resolution,
                    free_on_grid(source, alignment.transform, prepared.grid))
    parts = ()
    if cover.confidence < option.min_confidence and alignment.distinctiveness is not None:
        progress("placing the map's parts on their own")
        parts = tuple(place_parts(map_xy, prepared.xy, alignment.transform, option.params,
                                  target))
    cover = replace(cover, parts=parts,
                    verdict=verdict(cover.confidence, option.min_confidence, parts,
                                    alignment.distinctiveness, cover.truth_recall,
                                    cover.seen_through, alignment.free_on_truth))
    if cover.verdict == OTHER and not option.force:
        raise Refused(refusal(source, truth.path, alignment, cover, settings, map_xy,
                              prepared.xy))
    return Placed(given, source, registration, map_xy, map_level, alignment, map_occ, to_map,
                  cover, rule, target)


def check_footprint_rule(source: OccupancyMap | PointMap, settings: Settings) -> None:
    """SettingsRefused (one line, naming the map) when the map cannot follow
    ``settings.footprint.rule``, found before any work (``auto`` is resolved later)."""
    try:
        check_rule(settings.footprint.rule, isinstance(source, OccupancyMap),
                   views=isinstance(source, PointMap) and source.seen is not None)
    except ValueError as err:
        raise SettingsRefused(f"{source.path}: {err}") from None


def check_init_3d(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
                  settings: Settings) -> None:
    """SettingsRefused (one line, naming the map) when ``--init-3d`` is given and a side is
    not a 3D cloud: it starts a 3D registration. Found before any work."""
    if settings.alignment.init_3d is None:
        return
    flat = [s for s in (source, truth) if not (isinstance(s, PointMap) and s.is_3d)]
    if flat:
        raise SettingsRefused(f"{source.path}: --init-3d starts the 3D registration of two 3D "
                              f"clouds; {flat[0].path} is not a 3D cloud (--init x,y,yaw "
                              "places a plan)")


def check_stretch(source: OccupancyMap | PointMap, settings: Settings) -> None:
    """SettingsRefused (one line, naming the map) when the map carries its points' scans and
    the stretch asked for (``--stretch-3d``) cuts its run into too many stretches
    (:func:`~pcmapq.align.stretches.run_stretches`). Found before any work."""
    stretch = settings.map_3d.stretch
    if not isinstance(source, PointMap) or source.scan is None or not stretch:
        return
    try:
        run_stretches(source.scan, stretch)
    except ValueError as err:
        raise SettingsRefused(f"{source.path}: {err}") from None


def map_footprint_rule(source: OccupancyMap | PointMap, settings: Settings) -> str:
    """The footprint rule this map follows: ``settings.footprint.rule`` with ``auto`` resolved (see
    :func:`pcmapq.raster.footprint.footprint_rule`); a rule the map cannot follow is bad input."""
    image = isinstance(source, OccupancyMap)
    try:
        return footprint_rule(settings.footprint.rule, source.state == UNKNOWN if image else None,
                              source.grid.resolution if image else 0.0,
                              views=not image and source.seen is not None)
    except ValueError as err:
        raise SettingsRefused(f"{source.path}: {err}") from None


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
        occupied = points_to_grid(map_xy, grid, min_hits(source, settings),
                                  move=transform.apply)
        known = None
        if rule == "seen" and source.seen is not None:
            seen = seen_on(source.seen, transform, grid)
        (x0, y0), (x1, y1) = bounds(map_xy)
        corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    footprint = map_footprint(rule, occupied, grid, settings.footprint.margin, known=known,
                              rectangle=transform.apply(corners), seen=seen)
    return occupied, footprint


def align_clouds_3d(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
                    settings: Settings,
                    plan: tuple[PreparedTruth, RigidTarget] | None = None,
                    ) -> tuple[OccupancyMap | PointMap, Registration3D | None]:
    """When both sides are 3D clouds (and no guess or --no-align says otherwise), register them
    in 3D first; returns the map moved into the truth frame and the registration. ``plan``: the
    truth's plan and its points prepared for the 2D search, for the registration's second
    guess (:mod:`pcmapq.align.plan_guess`) where its global search fits the map poorly."""
    option = settings.alignment
    if not registered_in_3d(source, truth, settings):
        return source, None

    def second() -> np.ndarray | None:
        prepared, target = plan
        try:  # a map with no wall band in its own frame (a camera's axes) has no plan guess,
            # nor one that looks too large for its truth (a unit mistake: the search would take
            # minutes and gigabytes)
            map_xy, map_level = plan_points(source, settings)
            check_size(source, map_xy, prepared.xy, settings)
            return guess_from_plans(map_xy, map_level, prepared.xy, prepared.level,
                                    option.params, target)
        except (InputError, EvaluationError):
            return None

    levelled = plan is not None and plan[0].level is not None
    start = None if option.init_3d is None else np.reshape(option.init_3d, (4, 4))
    try:
        reg = align_3d(source.points, truth.points, voxel=option.voxel_3d, init=start,
                       second=second if levelled else None)
    except EvaluationError as error:
        voxel = "" if "voxel" in str(error) else f" at --voxel-3d {option.voxel_3d:g} m"
        raise EvaluationError(f"{source.path} against {truth.path}: {error}{voxel}"
                              f"{_unit_hint(source, truth)}") from None
    return replace(source, points=apply(reg.transform, source.points)), reg


def _unit_hint(source: PointMap, truth: PointMap) -> str:
    """What looks wrong with either cloud (:func:`~pcmapq.io.extent.hint`, the rule the
    truth's side and a map too large for its truth are refused by: a span of another unit,
    points far from the rest), as a clause naming it; empty when nothing does."""
    for side, option in ((source, MAP_CROP), (truth, TRUTH_CROP)):
        why = hint(side, option)
        if why:
            return f"; {side.path}: {why}"
    return ""


def check_size(source: OccupancyMap | PointMap, map_xy: np.ndarray, truth_xy: np.ndarray,
               settings: Settings) -> None:
    """EvaluationError (one line), before the global search, for a map :data:`OVERSIZE` times
    larger than the truth: with ``--scale auto``, even at the lowest scale it tries (another
    unit, or a much larger place); with the scale fixed, when the map also looks wrong in
    itself (:func:`~pcmapq.io.extent.hint`: cells not metres wide, points far from the rest, a
    span of another unit), the mistakes the truth's side is refused for, caught before the
    search across the map's size costs minutes and gigabytes. Not with a guess or no search."""
    option = settings.alignment
    if option.init is not None or not option.enabled:
        return
    lowest = option.params.scale_range[0] if option.scale else 1.0
    size = lowest * radius(map_xy) / max(radius(truth_xy), 1e-12)
    if size <= OVERSIZE:
        return
    why = hint(source, MAP_CROP)
    if option.scale:
        raise EvaluationError(f"{source.path}: at the lowest scale --scale auto tries "
                              f"({lowest:g}), the map is still {size:.0f} times the size of "
                              "the truth; "
                              f"{why or 'a map of a larger place, or in another unit'}")
    if why:
        raise EvaluationError(f"{source.path}: {size:.0f} times the size of the truth, too "
                              f"large to be a map of its place: {why}")


def free_space(source: OccupancyMap | PointMap, prepared: PreparedTruth) -> FreeSpace | None:
    """The evidence of the map's free space against the truth's occupied and known cells
    (:mod:`pcmapq.align.free_space`): the free cells of an image that also has unknown ones
    (:func:`observed_free`), or the area a cloud's scans saw (a map that ``pcmapq track``
    builds); None for a map that has neither. A truth image knows its free and occupied
    cells, a truth cloud every cell of its grid."""
    if isinstance(source, OccupancyMap):
        if not observed_free(source):
            return None
        free_xy = source.grid.cell_centres(source.state == FREE)
    elif source.seen is not None:
        rows, cols = np.nonzero(source.seen.cells)
        free_xy = (np.column_stack([cols, rows]) + np.add(source.seen.corner, 0.5)) * SEEN_CELL
    else:
        return None
    if len(free_xy) == 0:
        return None
    truth = prepared.source
    known = (truth.state != UNKNOWN if isinstance(truth, OccupancyMap)
             else np.ones(prepared.grid.shape, bool))
    return FreeSpace(free_xy, prepared.occupied, known | prepared.occupied, prepared.grid)


def observed_free(source: OccupancyMap) -> bool:
    """Whether an image's free cells say what its robot saw: it has unknown cells too (a ROS
    map of what was explored). A black-and-white image's white is its background, free by
    map_server's rule but not seen to be."""
    return bool((source.state == UNKNOWN).any())


def free_on_grid(source: OccupancyMap | PointMap, transform: Similarity2D,
                 grid: MetricGrid) -> np.ndarray | None:
    """The map's free cells drawn on the truth's ``grid`` under ``transform`` (bool): an
    image's free cells (:func:`observed_free`), or the area a cloud's scans saw; None for a
    map with neither."""
    if isinstance(source, OccupancyMap):
        if not observed_free(source):
            return None
        free = warp_state(source.state, source.grid, transform, grid) == FREE
        return free if free.any() else None
    return None if source.seen is None else seen_on(source.seen, transform, grid)


def align_plan(source: OccupancyMap | PointMap, map_xy: np.ndarray, truth_xy: np.ndarray,
               registration: Registration3D | None, settings: Settings,
               target: RigidTarget | None = None, free: FreeSpace | None = None) -> Alignment:
    """The 2D alignment of the map's plan points to the truth's (both (N, 2) metres, in their
    own frames): the search and ICP of :func:`pcmapq.align.align` (``target``: the truth's
    points prepared for it; ``free``: the map's free space, for a rigid alignment), or, after
    a 3D registration, the plan scored as it is."""
    option = settings.alignment
    if registration is None:
        check_size(source, map_xy, truth_xy, settings)
        return align(map_xy, truth_xy, option.params, init=option.init, refine=option.enabled,
                     scale=option.scale, target=target, free=free)
    return replace(align(map_xy, truth_xy, option.params, init=Similarity2D(), refine=False),
                   method="3d" if option.init_3d is None else "3d+init")
