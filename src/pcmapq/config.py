"""Settings: every option of a run in one object, every length in metres."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from pcmapq.features import DETECTORS
from pcmapq.io.occupancy import Thresholds
from pcmapq.metrics.distances import DEFAULT_TAUS
from pcmapq.transform import Similarity2D

#: Every registered detector (a module of :mod:`pcmapq.features` that defines ``DETECTOR``).
DETECTOR_NAMES = tuple(DETECTORS)


@dataclass(frozen=True)
class Settings:
    """Options of ``pcmapq eval``; defaults are the documented ones.

    map_resolution, truth_resolution: metres per pixel of an image that has no YAML (overrides
        the YAML's); for a cloud truth, the cell size of its grid (default ``cloud_resolution``).
    map_thresholds, truth_thresholds: map_server's occupied_thresh, free_thresh and negate for
        an image map / truth, overriding its YAML (``--map-occupied-thresh`` ...).
    cloud_resolution: cell size used for a point-cloud truth when none is given, metres.
    band_low, band_high: the wall band of a 3D cloud, metres above the floor.
    scale: estimate the map's scale too (a similarity); for maps whose resolution is unknown
        or wrong. A map image without resolution then starts from the truth's.
    init: initial guess of the map -> truth transform; skips the global step.
    align: False trusts the map's frame (``--no-align``): no global step, no ICP.
    fit_tolerance: a map point is an inlier of the alignment within this distance, metres.
    min_confidence: the map is taken to show another place when its ``confidence`` (see
        :func:`pcmapq.pipeline.confidence`) is below this.
    force: evaluate even when the confidence is below ``min_confidence``.
    footprint: how the map's footprint (the area it observed) is found, one of
        ``pcmapq.raster.footprint.FOOTPRINT_RULES``: ``known`` cells of an image, the area its
        ``walls`` enclose, ``all`` of its rectangle, or ``auto``: known cells for an image with
        unknown regions, walls for a binary image or a cloud.
    footprint_margin: the map's footprint is grown by this much, metres.
    threshold: largest distance between matched features, metres.
    min_hits: a cloud cell is occupied when it holds at least this many points; by default 2
        for a 3D cloud (its wall band stacks many points on a wall cell, and a lone outlier is
        dropped) and 1 for a 2D cloud (a laser map puts one or two points per wall cell).
    detectors: which detectors to run.
    taus: distance thresholds of the F-score, metres.
    voxel_3d: working voxel of the 3D registration when both sides are 3D clouds, metres
        (0.3 indoors; 0.5-1 for outdoor maps).
    full: score against the whole truth; by default truth features outside the map's footprint
        (the area it observed) are not counted as missing.
    """

    map_resolution: float | None = None
    truth_resolution: float | None = None
    map_thresholds: Thresholds | None = None
    truth_thresholds: Thresholds | None = None
    cloud_resolution: float = 0.05
    band_low: float = 0.3
    band_high: float = 2.0
    scale: bool = False
    init: Similarity2D | None = None
    align: bool = True
    fit_tolerance: float = 0.2
    min_confidence: float = 0.5
    force: bool = False
    footprint: str = "auto"
    footprint_margin: float = 0.3
    threshold: float = 0.5
    min_hits: int | None = None
    detectors: tuple[str, ...] = DETECTOR_NAMES
    full: bool = False
    taus: tuple[float, ...] = DEFAULT_TAUS
    voxel_3d: float = 0.3

    def to_dict(self) -> dict:
        """Every option as plain JSON types, in metres and degrees: ``init`` as
        ``{"x_m", "y_m", "yaw_deg"}``, tuples as lists, thresholds as dicts."""
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, Similarity2D):
                value = {"x_m": value.tx, "y_m": value.ty, "yaw_deg": value.yaw_deg}
            elif isinstance(value, Thresholds):
                value = asdict(value)
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out
