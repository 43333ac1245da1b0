"""The blocks only a result of two 3D clouds holds: the 3D registration, MapEval's AWD and
SCS, and the 3D consistency map. Truth frame, metres and degrees."""

from __future__ import annotations

from pcmapq.results.schema.base import Block, Matrix, Point3


class Region3D(Block):
    """One region of the 3D consistency map, registered to the truth on its own: where it is
    (its points' centroid) and the map's error there, where the map has it from where it fits
    the truth (a region the map has too low: dz_m < 0)."""

    x_m: float
    y_m: float
    z_m: float
    dx_m: float
    dy_m: float
    dz_m: float
    offset_m: float
    roll_deg: float
    pitch_deg: float
    yaw_deg: float
    points: int
    fitness_before: float
    fitness_after: float
    held: bool
    """Its geometry pins the fit in all six directions and it fits (its offset is sure)."""
    first_scan: int | None = None
    """A stretch of the run: its first scan (0: the run's first); null for a tile."""
    last_scan: int | None = None
    """A stretch of the run: its last scan; null for a tile."""


class ConsistencyMap3D(Block):
    """Two 3D clouds: the map, as the 3D registration placed it, cut into tiles of the ground
    (or, for a map that carries its points' scans, stretches of the run), each registered to
    the truth on its own in 3D; in the truth's levelled frame (x, y its plan, z up), metres and
    degrees. Largest: of the held regions; null without one."""

    tile_m: float | None
    """A tile's side; null when the regions are stretches of the run."""
    stretch_scans: int | None = None
    """The scans a stretch of the run holds; null when the regions are tiles."""
    voxel_m: float
    tolerance_m: float
    """A point within this of a truth point fits (fitness)."""
    largest_offset_m: float | None
    largest_at_m: Point3 | None
    largest_dz_m: float | None
    """The largest vertical offset, |dz|."""
    largest_dz_at_m: Point3 | None
    regions: list[Region3D]


class Map3D(Block):
    """MapEval's map figures of two 3D clouds in one frame (docs/metrics.md): each cloud cut
    into voxels, one Gaussian (mean, covariance) per voxel and cloud."""

    computed_on: str
    """The voxels, the points they need and SCS's neighbourhood, in words."""
    voxels: int
    """Voxels both clouds hold enough points in: AWD's mean is over them."""
    awd_m: float | None
    """AWD: the mean 2-Wasserstein distance between the two clouds' Gaussians of those voxels
    (lower is better); null when no voxel is compared."""
    scs: float | None
    """SCS: the mean, over those voxels, of their neighbours' distances' standard deviation
    over their mean (no unit; lower is better); null when no voxel has a neighbour."""


class Registration3D(Block):
    """The 3D registration of two clouds."""

    matrix: Matrix
    fitness: float
    rmse_m: float
