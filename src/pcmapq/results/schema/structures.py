"""The result's block of 3D structures (``structures_3d``; :mod:`pcmapq.match.structures`),
declared as the rest of the document is: truth frame,
metres and degrees."""

from __future__ import annotations

from pcmapq.core.stats import Stats
from pcmapq.results.schema.base import Block, Matrix, Point3


class Plane3D(Block):
    """A plane found on a 3D cloud, truth frame: ``normal . x = offset_m``."""

    normal: Point3
    """Unit normal, its largest component positive."""
    offset_m: float
    centroid_m: Point3
    """The mean of its points."""
    corners_m: tuple[Point3, Point3, Point3, Point3]
    """Its bounding rectangle in the plane, corners in order, the longer side first."""
    extent_m: tuple[float, float]
    """The rectangle's sides, longer first."""
    area_m2: float
    """What its points cover."""
    points: int
    """Its points in the cloud reduced to the structures' voxel."""


class Line3D(Block):
    """A line where two planes of a 3D cloud meet, truth frame."""

    direction: Point3
    """Unit direction, its largest component positive."""
    point_m: Point3
    """The middle of its segment."""
    length_m: float


class PlaneMatch(Block):
    """A truth plane and the map plane matched to it."""

    truth: Plane3D
    map: Plane3D
    displacement_m: float
    """Where the map plane lies from the truth plane, along the truth plane's normal (signed),
    at the middle of their overlap."""
    angle_deg: float


class LineMatch(Block):
    """A truth line and the map line matched to it."""

    truth: Line3D
    map: Line3D
    displacement_m: float
    """How far the map line passes from the truth line at the middle of their overlap (>= 0)."""
    angle_deg: float


class StructureScores(Block):
    """One detector's 3D structures matched one to one (the paper's quality q and more)."""

    quality: float | None
    precision: float | None
    f1: float | None
    note: str | None
    """Why a score is null."""
    truth_structures: int
    map_structures: int
    matched: int
    max_angle_deg: float
    max_offset_m: float
    displacement_m: Stats
    """Of the matched pairs' displacements' sizes."""
    angle_deg: Stats


class PlaneScores(StructureScores):
    """The planes' scores, and the planes: matched, missing (the truth's unmatched) and extra
    (the map's unmatched)."""

    matches: list[PlaneMatch]
    missing: list[Plane3D]
    extra: list[Plane3D]


class LineScores(StructureScores):
    """The plane lines' scores, and the lines: matched, missing and extra."""

    matches: list[LineMatch]
    missing: list[Line3D]
    extra: list[Line3D]


class PlaneFit3D(Block):
    """The planes' own fit: the rigid motion of the registered map onto the truth that the
    matched planes agree on (a robust fit: a few planes that moved do not pull it)."""

    applied: bool
    """Whether the map's planes and lines were moved by it before they were matched: it moves
    no matched map plane's corner further than ``reach_m``."""
    matrix: Matrix
    """The motion found, 4 x 4, the registered map to the truth frame."""
    centre_m: Point3
    """The matched map planes' centre."""
    offset_m: float
    """How far it moves that centre."""
    angle_deg: float
    """Its rotation."""
    largest_move_m: float
    """How far it moves the farthest corner of a matched map plane."""
    reach_m: float | None
    """The most it may: the 3D registration's last ICP correspondence distance."""
    planes_held: int
    """The matched planes it rests on (their final weight at least 0.5)."""
    planes_matched: int
    """The planes matched before it, which it was fitted to."""


class Structures3D(Block):
    """The 3D structures of two 3D clouds registered in 3D, each detector's, and the planes'
    own fit that moved the map's structures."""

    planes: PlaneScores
    plane_lines: LineScores
    fit: PlaneFit3D | None = None
    """Absent in a result written before the fit was made."""
