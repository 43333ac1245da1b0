"""Does pcmapq tell a map of the truth's place from a map of another place? Prints a markdown
table of same-place and different-place pairs of ../shared/data with the old rule (agreement =
fitness x truth recall, refused below 0.2) and the new one (``alignment.confidence``, refused
below 0.5).

    python tools/same_place.py [--data DIR] [--no-gazebo] [--matrix]

Same place: the Intel and Freiburg 079 SLAM maps against their plans and four Halmstad maps
against their layouts (scale estimated), the Gazebo SLAM map against its world, the shipped
sample, CARMEN maps built from drifted poses against the corrected map. Another place: every
CARMEN building against every other (rigid: both in metres), the four Halmstad maps against the
three other layouts, the Intel map against Freiburg's plan and back (scale estimated).
``--matrix`` adds a summary of every Halmstad map against every layout (144 pairs, about 5 min).
Runs score with ``force=True`` and no detectors: only the alignment and the overlap matter here.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pcmapq.config import AlignmentConfig, MatchingConfig, Settings, SourceConfig
from pcmapq.io import PointMap, Thresholds
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.pipeline import evaluate
from pcmapq.report.text import number
from pcmapq.result import Result

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"

#: Old rule: refused below this agreement; new rule: refused below this confidence.
OLD_MIN_AGREEMENT = 0.2
NEW_MIN_CONFIDENCE = Settings().min_confidence

#: Scale estimated, plan taken at 0.05 m per pixel (as tools/validate.py).
PLAN = Settings(alignment=AlignmentConfig(scale=True, force=True),
                truth=SourceConfig(resolution=0.05),
                matching=MatchingConfig(detectors=()))
#: Both sides metric.
RIGID = Settings(alignment=AlignmentConfig(force=True), matching=MatchingConfig(detectors=()))
#: The Intel SLAM map's walls are grey 127, its unexplored area grey 230.
INTEL_MAP = Thresholds(occupied=0.4, free=0.05)

HALMSTAD_MAPS = ("E5_09", "F5_01", "HIH_01", "KPT4A_01")
BUILDINGS = ("E5", "F5", "HIH", "KPT4A")
CARMEN = ("intel", "aces", "fhw", "csail", "orebro", "freiburg-079")
#: (log, drift level) of the drifted CARMEN maps (see tools/carmen_drift.py).
DRIFTS = (("intel", 0.001), ("intel", 0.005), ("fhw", 0.005))


@dataclass(frozen=True)
class Pair:
    """A map and a truth; same: whether they show one place. map_source: a path, or a cloud
    built here (drifted CARMEN maps)."""

    name: str
    same: bool
    map_source: Path | PointMap
    truth: Path
    settings: Settings


@dataclass(frozen=True)
class Row:
    """One pair's figures: mode ('rigid' / 'scale'), the search's distinctiveness (None without
    a search), truth recall, fitness, agreement, confidence, seconds."""

    pair: Pair
    mode: str
    distinct: float | None
    recall: float
    fitness: float
    agreement: float
    confidence: float
    seconds: float

    @property
    def old_ok(self) -> bool:
        """Accepted by the old rule (agreement)."""
        return self.agreement >= OLD_MIN_AGREEMENT

    @property
    def new_ok(self) -> bool:
        """Accepted by the new rule (confidence)."""
        return self.confidence >= NEW_MIN_CONFIDENCE


def halmstad(data: Path, name: str) -> Path:
    """A Halmstad robot map's image."""
    building = name.rsplit("_", 1)[0]
    return data / "halmstad" / "maps" / building / "pseudo_occupancy" / f"{name}.png"


def layout(data: Path, building: str) -> Path:
    """A Halmstad building's layout image."""
    return data / "halmstad" / "maps" / building / "layout" / f"{building}_layout.png"


def carmen(data: Path, name: str) -> Path:
    """A CARMEN log."""
    return data / "carmen" / f"{name}-corrected.log.gz"


def drifted_map(log: Path, level: float, seed: int = 0) -> PointMap:
    """The log's scans placed along its poses drifted at ``level`` (tools/carmen_drift.py)."""
    sys.path.insert(0, str(ROOT / "tools"))
    from carmen_drift import drifted

    poses, ranges, angles = read_flaser(log)
    xy = endpoints(drifted(poses, level, seed), ranges, angles, DEFAULT_MAX_RANGE)
    name = Path(f"{log.name} drift {100 * level:g} %")
    return PointMap(name, np.column_stack([xy, np.zeros(len(xy))]), False)


def pairs(data: Path, gazebo: bool = True) -> Iterator[Pair]:
    """Every pair of the table, same-place ones first."""
    plans = data / "floorplans"
    intel = replace(PLAN, map_thresholds=INTEL_MAP)
    yield Pair("Intel map vs its plan", True, plans / "intel_map.png", plans / "lab_intel.png",
               intel)
    yield Pair("Freiburg 079 map vs its plan", True, plans / "freiburg_building79.png",
               plans / "Freiburg79_scan.png", PLAN)
    for name in HALMSTAD_MAPS:
        yield Pair(f"{name} vs its layout", True, halmstad(data, name),
                   layout(data, name.rsplit("_", 1)[0]), PLAN)
    if gazebo:
        folder = data / "gazebo"
        yield Pair("Gazebo SLAM map vs its world", True, folder / "SLAM_Gen_Map.png",
                   folder / "Ground_Truth.png",
                   replace(PLAN, truth_resolution=1.0 / 529.0))
    yield Pair("sample scan vs its plan", True, ROOT / "data" / "sample" / "scan.ply",
               ROOT / "data" / "sample" / "truth.png", RIGID)
    for log, level in DRIFTS:
        yield Pair(f"{log} drifted {100 * level:g} % vs corrected", True,
                   drifted_map(carmen(data, log), level), carmen(data, log), RIGID)
    yield Pair("Intel map vs Freiburg's plan", False, plans / "intel_map.png",
               plans / "Freiburg79_scan.png", intel)
    yield Pair("Freiburg 079 map vs Intel's plan", False, plans / "freiburg_building79.png",
               plans / "lab_intel.png", PLAN)
    for name in HALMSTAD_MAPS:
        own = name.rsplit("_", 1)[0]
        for other in BUILDINGS:
            if other != own:
                yield Pair(f"{name} vs {other} layout", False, halmstad(data, name),
                           layout(data, other), PLAN)
    for a in CARMEN:
        for b in CARMEN:
            if a != b:
                yield Pair(f"CARMEN {a} vs {b}", False, carmen(data, a), carmen(data, b), RIGID)


def measure(pair: Pair) -> Row:
    """Run one pair and keep its figures."""
    start = time.perf_counter()
    result: Result = evaluate(pair.map_source, pair.truth, pair.settings)
    a, o = result.alignment, result.overlap
    return Row(pair, "scale" if pair.settings.scale else "rigid", a.distinctiveness,
               o.truth_recall, a.fitness, o.agreement, o.confidence,
               time.perf_counter() - start)


def _verdict(ok: bool, same: bool) -> str:
    """'accepted' / 'refused', in bold when wrong."""
    word = "accepted" if ok else "refused"
    return word if ok == same else f"**{word}**"


def markdown(rows: list[Row]) -> str:
    """The table, and how many pairs each rule gets wrong."""
    lines = ["| pair | place | search | fitness | truth recall | agreement (before) | "
             "distinctiveness | confidence (after) | before | after | s |",
             "|" + " --- |" * 11]
    for r in rows:
        lines.append("| " + " | ".join([
            r.pair.name, "same" if r.pair.same else "other", r.mode, number(r.fitness, 2),
            *(number(v, 2) for v in (r.recall, r.agreement, r.distinct, r.confidence)),
            _verdict(r.old_ok, r.pair.same), _verdict(r.new_ok, r.pair.same),
            f"{r.seconds:.1f}"]) + " |")
    lines += ["", summary(rows)]
    return "\n".join(lines)


def summary(rows: list[Row]) -> str:
    """One line: wrong verdicts of each rule among same-place and other-place pairs."""
    same = [r for r in rows if r.pair.same]
    other = [r for r in rows if not r.pair.same]
    return (f"{len(same)} same-place pairs: refused before {sum(not r.old_ok for r in same)}, "
            f"after {sum(not r.new_ok for r in same)}; {len(other)} other-place pairs: "
            f"accepted before {sum(r.old_ok for r in other)}, after "
            f"{sum(r.new_ok for r in other)}.")


def matrix(data: Path) -> str:
    """Every Halmstad map against every layout: the summary line and the wrong verdicts."""
    rows = []
    for path in sorted((data / "halmstad" / "maps").glob("*/pseudo_occupancy/*.png")):
        own = path.parents[1].name
        for building in BUILDINGS:
            pair = Pair(f"{path.stem} vs {building} layout", building == own, path,
                        layout(data, building), PLAN)
            rows.append(measure(pair))
    wrong = [r for r in rows if r.new_ok != r.pair.same]
    lines = [f"Every Halmstad map against every layout: {summary(rows)}"]
    lines += [f"- {r.pair.name}: distinctiveness {number(r.distinct, 2)}, "
              f"recall {number(r.recall, 2)}, confidence {number(r.confidence, 2)}" for r in wrong]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA,
                        help="the shared data folder (default: %(default)s)")
    parser.add_argument("--no-gazebo", action="store_true",
                        help="skip the Gazebo pair (62 M truth cells, about 20 s)")
    parser.add_argument("--matrix", action="store_true",
                        help="also every Halmstad map against every layout (about 5 min)")
    args = parser.parse_args(argv)
    if not args.data.is_dir():
        print(f"{args.data}: absent (real data lives in ../shared/data)", file=sys.stderr)
        return 2
    rows = [measure(p) for p in pairs(args.data, gazebo=not args.no_gazebo)]
    print(markdown(rows), flush=True)
    if args.matrix:
        print("\n" + matrix(args.data))
    return 0


if __name__ == "__main__":
    sys.exit(main())
