"""Same place or another place: the pairs of real maps and truths that tell them apart, each
labelled (the same place or not) and with the settings it is scored with (``force`` and no
detectors). Same place: the Intel and Freiburg 079 SLAM maps against their plans and four
Halmstad maps against their layouts (scale estimated), the Gazebo SLAM map against its world,
the shipped sample, CARMEN maps built from drifted poses against the corrected map. Another
place: every CARMEN building against every other (rigid: both in metres), the four Halmstad
maps against the three other layouts, the Intel map against Freiburg's plan and back. Then
every Halmstad map against every layout (the matrix)."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pcmapq.io import PointMap
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings, SourceConfig

from .. import drift
from ..paths import SAMPLE
from . import gazebo, halmstad
from .floorplans import FLOORPLANS

#: The confidence: refused below this.
NEW_MIN_CONFIDENCE = Settings().alignment.min_confidence
#: Scale estimated, plan taken at 0.05 m per pixel (as the floor plans and Halmstad).
PLAN = Settings(alignment=AlignmentConfig(scale=True, force=True),
                truth=SourceConfig(resolution=0.05),
                matching=MatchingConfig(detectors=()))
#: Both sides metric.
RIGID = Settings(alignment=AlignmentConfig(force=True), matching=MatchingConfig(detectors=()))
BUILDINGS = ("E5", "F5", "HIH", "KPT4A")
CARMEN = ("intel", "aces", "fhw", "csail", "orebro", "freiburg-079")
#: (log, drift level) of the drifted CARMEN maps (see :mod:`testkit.drift`), seed 0.
DRIFTS = (("intel", 0.001), ("intel", 0.005), ("fhw", 0.005))


@dataclass(frozen=True)
class Pair:
    """A map and a truth; same: whether they show one place; case: its reference's name.
    map_source: a path, or how to build the map (drifted CARMEN maps)."""

    name: str
    case: str
    same: bool
    map_source: Path | Callable[[], PointMap]
    truth: Path
    settings: Settings


def layout(data: Path, building: str) -> Path:
    """A Halmstad building's layout image."""
    return data / "halmstad" / "maps" / building / "layout" / f"{building}_layout.png"


def carmen(data: Path, name: str) -> Path:
    """A CARMEN log."""
    return data / "carmen" / f"{name}-corrected.log.gz"


def drifted_map(log: Path, level: float, seed: int = 0) -> PointMap:
    """The log's scans placed along its poses drifted at ``level``."""
    poses, ranges, angles = read_flaser(log)
    xy = endpoints(drift.drifted(poses, level, seed), ranges, angles, DEFAULT_MAX_RANGE)
    name = Path(f"{log.name} drift {100 * level:g} %")
    return PointMap(name, np.column_stack([xy, np.zeros(len(xy))]), False)


def _slug(text: str) -> str:
    return "same-place-" + re.sub(r"[^a-z0-9_]+", "-", text.lower()).strip("-")


def halmstad_pair(data: Path, name: str, building: str, label: str) -> Pair:
    """A Halmstad map against a building's layout."""
    own = name.rsplit("_", 1)[0]
    return Pair(label, _slug(f"{name} vs {building} layout"), building == own,
                halmstad.paths(data, name)[0], layout(data, building), PLAN)


def pairs(data: Path) -> Iterator[Pair]:
    """Every pair of the table, same-place ones first."""
    plans = data / "floorplans"
    intel = replace(PLAN, map=SourceConfig(thresholds=FLOORPLANS[0].thresholds))

    def pair(name: str, same: bool, map_source, truth: Path, settings: Settings) -> Pair:
        return Pair(name, _slug(name), same, map_source, truth, settings)

    yield pair("Intel map vs its plan", True, plans / "intel_map.png", plans / "lab_intel.png",
               intel)
    yield pair("Freiburg 079 map vs its plan", True, plans / "freiburg_building79.png",
               plans / "Freiburg79_scan.png", PLAN)
    for name in halmstad.MAPS:
        yield halmstad_pair(data, name, name.rsplit("_", 1)[0], f"{name} vs its layout")
    folder = data / "gazebo"
    yield pair("Gazebo SLAM map vs its world", True, folder / gazebo.MAP, folder / gazebo.TRUTH,
               replace(PLAN, truth=SourceConfig(resolution=gazebo.RESOLUTION)))
    yield pair("sample scan vs its plan", True, SAMPLE / "scan.ply",
               SAMPLE / "truth.png", RIGID)
    for log, level in DRIFTS:
        yield pair(f"{log} drifted {100 * level:g} % vs corrected", True,
                   lambda log=log, level=level: drifted_map(carmen(data, log), level),
                   carmen(data, log), RIGID)
    yield pair("Intel map vs Freiburg's plan", False, plans / "intel_map.png",
               plans / "Freiburg79_scan.png", intel)
    yield pair("Freiburg 079 map vs Intel's plan", False, plans / "freiburg_building79.png",
               plans / "lab_intel.png", PLAN)
    for name in halmstad.MAPS:
        for other in BUILDINGS:
            if other != name.rsplit("_", 1)[0]:
                yield halmstad_pair(data, name, other, f"{name} vs {other} layout")
    for a in CARMEN:
        for b in CARMEN:
            if a != b:
                yield pair(f"CARMEN {a} vs {b}", False, carmen(data, a), carmen(data, b), RIGID)


def matrix_pairs(data: Path) -> list[Pair]:
    """Every Halmstad map against every layout."""
    return [halmstad_pair(data, path.stem, b, f"{path.stem} vs {b} layout")
            for path in sorted((data / "halmstad" / "maps").glob("*/pseudo_occupancy/*.png"))
            for b in BUILDINGS]
