"""The settings' groups, one frozen dataclass per pipeline stage, and :class:`Settings` holding
them all; every length in metres. Each default is defined here once (or, where a light module
below the settings holds it, imported from there); the option table, the command line's help,
the settings file and the docs read it from here. Light: the defaults come from modules that
load no pipeline (the detectors' names, the metrics' defaults), so that the command line's
help, which shows them, loads none of it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from pcmapq.align.params import AlignParams
from pcmapq.core.bounds import Box
from pcmapq.core.transform import Similarity2D
from pcmapq.features.names import DEFAULT_DETECTORS, MATCH_THRESHOLD
from pcmapq.io.map_yaml import Thresholds
from pcmapq.metrics.defaults import (
    AWD_MIN_POINTS,
    AWD_VOXEL,
    DEFAULT_TAUS,
    LIDAR_RADIUS,
    MAX_NN,
    MAX_WARD_POINTS,
    MIN_KNN,
    SCS_RADIUS,
)
from pcmapq.settings.plain import plain


def default_params() -> dict[str, Any]:
    """The default parameters of the detectors run by default, by name
    (:func:`pcmapq.features.registry.default_params`; loads the detectors)."""
    from pcmapq.features.registry import default_params as of_detectors

    return of_detectors()


@dataclass(frozen=True)
class SourceConfig:
    """How one input is read (load stage).

    resolution: metres per pixel of an image that has no YAML (overrides the YAML's); for a
        cloud truth, the cell size of its grid (default ``RasterConfig.cloud_resolution``).
    thresholds: map_server's occupied_thresh, free_thresh and negate for an image, overriding
        its YAML (``--map-occupied-thresh`` ...).
    crop: keep only the part inside this box ``(x0, y0, x1, y1)``, metres, in the input's own
        frame (``--map-crop``, ``--truth-crop``; see :mod:`pcmapq.io.extent`).
    topic: a ROS recording's OccupancyGrid topic (``--map-topic``, ``--truth-topic``; None:
        its only one, or ``/map``).
    at: the recording's map at this time, seconds from the recording's start (the last
        recorded at or before it; ``--at`` for the map); None: its last.
    """

    resolution: float | None = None
    thresholds: Thresholds | None = None
    crop: Box | None = None
    topic: str | None = None
    at: float | None = None


#: Points that mark a cloud's cell occupied when ``RasterConfig.min_hits`` is None: a 3D cloud's,
#: a 2D cloud's.
MIN_HITS_3D, MIN_HITS_2D = 2, 1


@dataclass(frozen=True)
class RasterConfig:
    """How inputs become plans and grids (raster stage).

    cloud_resolution: cell size used for a point-cloud truth when none is given, metres.
    band_low, band_high: the wall band of a 3D cloud, metres above the floor.
    min_hits: a cloud cell is occupied when it holds at least this many points; None:
        :data:`MIN_HITS_3D` for a 3D cloud (its wall band stacks many points on a wall cell, and
        a lone outlier is dropped), :data:`MIN_HITS_2D` for a 2D cloud (a laser map puts one or
        two points per wall cell).
    """

    cloud_resolution: float = 0.05
    band_low: float = 0.3
    band_high: float = 2.0
    min_hits: int | None = None


@dataclass(frozen=True)
class AlignmentConfig:
    """How the map is put in the truth's frame (align stage).

    enabled: False trusts the map's frame (``--no-align``): no global step, no ICP.
    init: initial guess of the map -> truth transform; skips the global step.
    init_3d: two 3D clouds: the 3D registration's start, a rigid 4x4 map -> truth transform
        (row-major, 16 numbers, metres; ``--init-3d``): no global search, its ICP starts there.
    scale: estimate the map's scale too (a similarity); for maps whose resolution is unknown
        or wrong. A map image without resolution then starts from the truth's.
    voxel_3d: working voxel of the 3D registration when both sides are 3D clouds, metres
        (0.3 indoors; 0.5-1 for outdoor maps).
    min_confidence: the map is taken to show another place when its ``confidence`` (see
        :func:`pcmapq.evaluation.same_place.confidence`) is below this.
    force: evaluate even when the confidence is below ``min_confidence``.
    params: the 2D alignment's tunables (:class:`~pcmapq.align.AlignParams`: the inlier
        tolerance, voxel, global search cell, candidates, finalists, scale range).
    """

    enabled: bool = True
    init: Similarity2D | None = None
    init_3d: tuple[float, ...] | None = None
    scale: bool = False
    voxel_3d: float = 0.3
    min_confidence: float = 0.5
    force: bool = False
    params: AlignParams = field(default_factory=AlignParams)


@dataclass(frozen=True)
class FootprintConfig:
    """What part of the truth the map is scored against.

    rule: how the map's footprint (the area it observed) is found, one of
        ``pcmapq.raster.footprint.FOOTPRINT_RULES``: ``known`` cells of an image, the area its
        ``walls`` enclose, ``all`` of its rectangle, or ``auto``: known cells for an image with
        unknown regions, walls for a binary image or a cloud.
    margin: the map's footprint is grown by this much, metres.
    full: score against the whole truth; by default truth features outside the map's footprint
        are not counted as missing.
    """

    rule: str = "auto"
    margin: float = 0.3
    full: bool = False


@dataclass(frozen=True)
class MatchingConfig:
    """Which features are found and when two match (features and match stages).

    detectors: which detectors to run (default: those run by default, not ``rooms``).
    threshold: largest distance between matched features, metres.
    params: each detector's parameters by name (its ``Params``, lengths in metres; see
        :func:`pcmapq.features.default_params`); a detector left out uses its defaults.
    """

    detectors: tuple[str, ...] = DEFAULT_DETECTORS
    threshold: float = MATCH_THRESHOLD
    params: dict[str, Any] = field(default_factory=default_params, hash=False)


@dataclass(frozen=True)
class DistancesConfig:
    """The distance metrics (metrics stage). taus: thresholds of the F-score, metres."""

    taus: tuple[float, ...] = DEFAULT_TAUS


@dataclass(frozen=True)
class NoRefConfig:
    """The no-reference figures of each input (:mod:`pcmapq.evaluation.noref_figures`, ``pcmapq
    inspect``).

    enabled: ``eval`` reports them for the map and the truth (``--no-noref``: not).
    radius: the 3D figures' neighbourhood, metres (1.0 for LiDAR maps, 0.2 for depth cameras).
    min_knn: a point counts in MME and MPV with more than this many neighbours.
    max_nn: nearest neighbours of the normals that pick MOM's orthogonal planes.
    voxel: a 3D cloud is first reduced to the centroid of its points in each cell of this
        size, metres (0: as it is, as map-metrics; ``eval`` uses ``EVAL_NOREF_VOXEL``).
    max_ward: MOM's planes are clustered by a Ward tree of at most this many planar normals
        (``eval`` uses ``EVAL_MAX_WARD``; see :mod:`pcmapq.metrics.orthogonal`).
    sample: MME and MPV are means over this many of the (reduced) cloud's points drawn at
        random, seeded, with their standard errors, and MOM's planes are found among them (0:
        every point, as map-metrics; ``eval`` uses ``EVAL_NOREF_SAMPLE``).
    """

    enabled: bool = True
    radius: float = LIDAR_RADIUS
    min_knn: int = MIN_KNN
    max_nn: int = MAX_NN
    voxel: float = 0.0
    max_ward: int = MAX_WARD_POINTS
    sample: int = 0


#: ``eval``'s voxel for the 3D no-reference figures, metres: a tenth of LiDAR's radius. It bounds
#: their cost on dense clouds and puts maps of unlike density on one footing (MME depends on it).
EVAL_NOREF_VOXEL = 0.1
#: ``eval``'s sample for the 3D no-reference figures: enough for MME within about 0.01 nats
#: (docs/metrics.md gives the measured errors), at a small share of an evaluation.
EVAL_NOREF_SAMPLE = 20_000
#: ``eval``'s Ward tree for MOM's planes: 2,000 normals, a small share of the run (the tree's
#: time grows with the square of the normals).
EVAL_MAX_WARD = 2_000
#: ``track``'s steps: every this many scans of a run when no other rule is given (``--every``).
TRACK_EVERY = 20


@dataclass(frozen=True)
class Map3DConfig:
    """The figures of two 3D clouds: MapEval's AWD and SCS (:mod:`pcmapq.metrics.map_gaussians`;
    MapEval's defaults) and the 3D consistency map. A result records this group only when it
    has some of them.

    voxel: the voxels' side, metres. min_points: the points a voxel needs in each cloud to be
    compared. radius: SCS's neighbourhood, in voxels along each axis. tile: side of the tiles
    of the 3D consistency map (each tile of the map registered to the truth on its own,
    :mod:`pcmapq.align.regions3d`), metres. stretch: for a map that carries its points' scans,
    the scans a stretch of the run holds, its 3D consistency map's regions instead of tiles;
    None: as many as cut the run into at most 32 stretches, at least 4; 0: tiles.
    """

    voxel: float = AWD_VOXEL
    min_points: int = AWD_MIN_POINTS
    radius: int = SCS_RADIUS
    tile: float = 8.0
    stretch: int | None = None


@dataclass(frozen=True)
class StructuresConfig:
    """The 3D structures of two 3D clouds registered in 3D (:mod:`pcmapq.match.structures`):
    their planes and the lines where two planes meet, found on each cloud in the truth frame
    and matched one to one. A result records this group only when it has them.

    enabled: find and match them (``--no-structures``: not).
    voxel: each cloud is reduced to one point per voxel of this side before its planes are
        found, metres (0.1 indoors; 0.3 for outdoor LiDAR maps).
    min_points: the fewest reduced points a plane keeps.
    min_area: the least area a plane covers, square metres.
    max_angle: the largest angle between a matched truth and map structure, degrees.
    max_offset: the largest distance between them, metres: a plane's along the truth plane's
        normal, a line's from the truth line.
    line_margin: two planes meet in a line where their extents touch within this, metres.
    line_length: the shortest line counted, metres (its segment, which reaches the margin
        beyond where the planes end): shorter lines are where two planes barely touch (on a
        street, mostly two small planes of 1-3 square metres), and come and go with each
        pass of a scanner.
    """

    enabled: bool = True
    voxel: float = 0.1
    min_points: int = 30
    min_area: float = 1.0
    max_angle: float = 5.0
    max_offset: float = 0.5
    line_margin: float = 0.2
    line_length: float = 1.5


@dataclass(frozen=True)
class Settings:
    """Options of ``pcmapq eval``, one group per stage; defaults are the documented ones.

    ``Settings(alignment=AlignmentConfig(scale=True), matching=MatchingConfig(threshold=0.3))``
    changes two options and keeps every other default.
    """

    map: SourceConfig = field(default_factory=SourceConfig)
    truth: SourceConfig = field(default_factory=SourceConfig)
    raster: RasterConfig = field(default_factory=RasterConfig)
    alignment: AlignmentConfig = field(default_factory=AlignmentConfig)
    footprint: FootprintConfig = field(default_factory=FootprintConfig)
    matching: MatchingConfig = field(default_factory=MatchingConfig)
    distances: DistancesConfig = field(default_factory=DistancesConfig)
    noref: NoRefConfig = field(default_factory=lambda: NoRefConfig(
        voxel=EVAL_NOREF_VOXEL, max_ward=EVAL_MAX_WARD, sample=EVAL_NOREF_SAMPLE))
    map_3d: Map3DConfig = field(default_factory=Map3DConfig)
    structures: StructuresConfig = field(default_factory=StructuresConfig)

    def to_dict(self) -> dict:
        """Every option as plain JSON types, one object per stage, in metres and degrees:
        ``init`` as ``{"x_m", "y_m", "yaw_deg", "scale"}``, tuples as lists."""
        return plain(self)

    @classmethod
    def from_dict(cls, doc: dict) -> Settings:
        """The inverse of :meth:`to_dict` (e.g. the ``settings`` of a saved result)."""
        from pcmapq.features.registry import detector

        def source(d: dict) -> SourceConfig:
            t = d["thresholds"]
            crop = d.get("crop")
            return SourceConfig(d["resolution"], None if t is None else Thresholds(**t),
                                None if crop is None else tuple(crop), d.get("topic"),
                                d.get("at"))

        a, m = doc["alignment"], doc["matching"]
        init = a["init"]
        return cls(
            map=source(doc["map"]), truth=source(doc["truth"]),
            raster=RasterConfig(**doc["raster"]),
            alignment=AlignmentConfig(**{
                **a, "init": None if init is None else Similarity2D.from_dict(init),
                "init_3d": None if a.get("init_3d") is None else tuple(a["init_3d"]),
                "params": AlignParams(**{**a["params"], "scale_range": tuple(
                    a["params"]["scale_range"])})}),
            footprint=FootprintConfig(**doc["footprint"]),
            matching=MatchingConfig(tuple(m["detectors"]), m["threshold"],
                                    {name: detector(name).params(**p)
                                     for name, p in m["params"].items()}),
            distances=DistancesConfig(tuple(doc["distances"]["taus"])),
            noref=NoRefConfig(**doc.get("noref", {"enabled": False})),  # saved before noref
            map_3d=Map3DConfig(**doc.get("map_3d", {})),  # absent without two 3D clouds
            structures=StructuresConfig(**doc.get("structures", {})))
