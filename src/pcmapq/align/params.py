"""The tunables of the 2D alignment, defined once (their defaults are the documented ones)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class AlignParams:
    """Tunables of :func:`pcmapq.align.align`. Lengths in truth units: metres (layout pixels
    for a truth given in pixels).

    tolerance: a map point within this distance of a truth point is an inlier (fitness, RMSE;
        the pairs of the scaled point-to-line stage), metres.
    voxel: both clouds are voxel-downsampled to this cell before anything else (the map at the
        current scale when the scale is free), metres; fitness and RMSE are measured on them.
    max_points: rigid alignment: a map with more voxels than this is downsampled again with
        the voxel grown in proportion (walls are lines: about this many points remain), so
        the search and ICP on a large map cost about what they cost on one of this size; the
        truth likewise beyond ten times as many. A thinned map's point-to-point ICP stages run
        on a few thousand of its points (:data:`pcmapq.align.planar.ICP_POINTS`).
    resolution: raster cell of the global search's sweep, metres; None: the map's radius / 40,
        at least 0.25 m (rigid), or the truth's radius / 20 (scale free, where it also sets the
        ICP stages).
    finest: rigid search: a sweep coarser than this is refined through rasters of half the cell
        each down to at most this cell, metres (:func:`pcmapq.align.pyramid.descend`); maps up
        to 80 m from their centroid (a building's) are swept at this cell or finer and not
        refined; a campus's is swept coarser and descends.
    beam: poses kept per level of that descent.
    top_k: candidate poses of the global search, each refined by a rough ICP stage.
    finalists: how many of those, by fitness, go through the fine stages and the point-to-line
        finish; None: 2 rigid, 3 with the scale free (the rough stage ranks less surely
        there, so the right pose may come third).
    scale_range: (lowest, highest) scale of a map of unknown unit, truth units per map unit.
    """

    tolerance: float = 0.2
    voxel: float = 0.05
    max_points: int = 200_000
    resolution: float | None = None
    finest: float = 2.0
    beam: int = 48
    top_k: int = 6
    finalists: int | None = None
    scale_range: tuple[float, float] = (0.2, 5.0)

    def finalists_for(self, scale: bool) -> int:
        """``finalists``, or its default: 3 with the scale free, else 2."""
        if self.finalists is not None:
            return self.finalists
        return 3 if scale else 2
