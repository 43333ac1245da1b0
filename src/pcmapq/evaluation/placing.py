"""The map put into the truth's frame before it is drawn: two 3D clouds registered in 3D,
then the 2D alignment of the plans (the global search and ICP of :func:`pcmapq.align.align`),
or the plan scored as it is after a 3D registration; and the check, before the search, that
the map's size can be the truth's at all."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from pcmapq.align import Alignment, align
from pcmapq.align.planar import RigidTarget
from pcmapq.align.rigid3d import Registration3D, align_3d, apply
from pcmapq.core.bounds import radius
from pcmapq.core.errors import EvaluationError
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.inputs import MAP_CROP
from pcmapq.evaluation.same_place import OVERSIZE
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.extent import hint
from pcmapq.settings import Settings


def align_clouds_3d(source: OccupancyMap | PointMap, truth: OccupancyMap | PointMap,
                    settings: Settings) -> tuple[OccupancyMap | PointMap, Registration3D | None]:
    """When both sides are 3D clouds (and no guess or --no-align says otherwise), register them
    in 3D first; returns the map moved into the truth frame and the registration."""
    both_3d = all(isinstance(s, PointMap) and s.is_3d for s in (source, truth))
    option = settings.alignment
    if not (both_3d and option.enabled and option.init is None and not option.scale):
        return source, None
    reg = align_3d(source.points, truth.points, voxel=option.voxel_3d)
    return replace(source, points=apply(reg.transform, source.points)), reg


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


def align_plan(source: OccupancyMap | PointMap, map_xy: np.ndarray, truth_xy: np.ndarray,
               registration: Registration3D | None, settings: Settings,
               target: RigidTarget | None = None) -> Alignment:
    """The 2D alignment of the map's plan points to the truth's (both (N, 2) metres, in their
    own frames): the search and ICP of :func:`pcmapq.align.align` (``target``: the truth's
    points prepared for it), or, after a 3D registration, the plan scored as it is."""
    option = settings.alignment
    if registration is None:
        check_size(source, map_xy, truth_xy, settings)
        return align(map_xy, truth_xy, option.params, init=option.init, refine=option.enabled,
                     scale=option.scale, target=target)
    return replace(align(map_xy, truth_xy, option.params, init=Similarity2D(), refine=False),
                   method="3d")
