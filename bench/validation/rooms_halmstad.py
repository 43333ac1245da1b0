"""Rooms of real robot maps: the 36 Halmstad maps against their buildings' layouts, scored by
the four detectors, beside each map's keypoint residual (how far its annotated keypoints land
from the layout's under pcmapq's alignment): does a worse map score worse rooms?"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.text import score
from pcmapq.testing.realdata.halmstad import (
    SETTINGS,
    halmstad_truth,
    keypoint_pairs,
    keypoint_residual,
    paths,
)

from .common import Case, Record, Section, header, row
from .rooms_drift import rho

BUILDINGS = ("E5", "F5", "HIH", "KPT4A")
DETECTORS = ("harris", "hough", "sift", "rooms")
ROOMS_SETTINGS = replace(SETTINGS, matching=replace(SETTINGS.matching, detectors=DETECTORS))


@dataclass(frozen=True)
class Scored:
    """One map: its keypoint residual (layout pixels of 0.05 m) and each detector's quality
    and f1, with the rooms' statuses."""

    name: str
    residual_px: float
    quality: dict[str, float | None]
    f1: dict[str, float | None]
    rooms: dict[str, int]

    def summary(self) -> dict:
        return {"residual_px": round(self.residual_px, 6),
                "quality": {k: None if v is None else round(v, 6)
                            for k, v in self.quality.items()},
                "rooms": self.rooms}


def names(data: Path, building: str) -> list[str]:
    """The building's maps, in order."""
    folder = data / "halmstad" / "maps" / building / "pseudo_occupancy"
    return sorted(p.stem for p in folder.glob(f"{building}_*.png"))


def scored(data: Path, name: str) -> Scored:
    """One map through the pipeline against its layout, with all four detectors."""
    building = name.rsplit("_", 1)[0]
    map_path, layout = paths(data, name)
    with tempfile.TemporaryDirectory(prefix="pcmapq_halmstad_rooms_") as tmp:
        result = evaluate(map_path, halmstad_truth(layout, Path(tmp)), ROOMS_SETTINGS)
    residual = keypoint_residual(result, map_path, *keypoint_pairs(data / "halmstad", name,
                                                                   building))
    return Scored(name, residual,
                  {k: d.matching.quality for k, d in result.detectors.items()},
                  {k: d.matching.f1 for k, d in result.detectors.items()},
                  result.rooms["counts"] if result.rooms else {})


def cases(data: Path) -> list[Case]:
    return [Case(f"halmstad-rooms-{name}", lambda name=name: scored(data, name))
            for building in BUILDINGS for name in names(data, building)]


def section(data: Path, record: Record) -> Section:
    """Per building: each map's residual and qualities, and the rank correlation of each
    detector's quality with the residual."""
    got = [case.run(record) for case in cases(data)]
    lines, rhos = [], []
    for building in BUILDINGS:
        maps = [g for g in got if g.name.rsplit("_", 1)[0] == building]
        residual = [m.residual_px for m in maps]
        rhos.append(row([building, str(len(maps)),
                         *(f"{rho(residual, [m.quality[d] for m in maps]):.2f}"
                           for d in DETECTORS)]))
        lines += [row([m.name, f"{m.residual_px:.1f}",
                       *(score(m.quality[d], 2) for d in DETECTORS),
                       ", ".join(f"{n} {k.replace('truth ', '')}" for k, n in m.rooms.items()
                                 if k.startswith("truth ") and "door" not in k)])
                  for m in maps]
    return Section("\n".join([
        "## Rooms of real robot maps: Halmstad against the layouts", "",
        f"The {len(got)} Halmstad maps of four buildings (the Halmstad section's data and "
        "settings), "
        "each scored against its building's layout with `--detectors "
        f"{','.join(DETECTORS)}`. The residual is the median distance, layout pixels of "
        "0.05 m, from each annotated map keypoint carried by pcmapq's alignment to its layout "
        "keypoint: a map that is bent or stretched has a larger one. rho: Spearman's rank "
        "correlation of each detector's quality with the residual over a building's maps "
        "(-1: the quality falls wherever the residual grows).", "",
        header(["building", "maps", *(f"rho {d}" for d in DETECTORS)]),
        *rhos, "",
        header(["map", "residual px", *(f"q {d}" for d in DETECTORS), "truth rooms"]),
        *lines,
    ]))
