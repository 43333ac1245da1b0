"""Rooms of real robot maps: the 36 Halmstad maps against their buildings' layouts, scored by
the four detectors, beside two residuals of each map's annotated keypoints (how far they land
from the layout's under pcmapq's alignment, and under their own least-squares fit): does a
worse map score worse rooms?"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.text import score
from testkit.realdata.halmstad import (
    BROKEN_ANNOTATIONS,
    SETTINGS,
    fit_residual,
    halmstad_truth,
    keypoint_pairs,
    keypoint_residual,
    paths,
)

from .common import Case, Record, Section, header, row
from .noref import rho

BUILDINGS = ("E5", "F5", "HIH", "KPT4A")
DETECTORS = ("harris", "hough", "sift", "rooms")
ROOMS_SETTINGS = replace(SETTINGS, matching=replace(SETTINGS.matching, detectors=DETECTORS))


@dataclass(frozen=True)
class Scored:
    """One map: its keypoint residuals (layout pixels of 0.05 m; None where its annotation is
    broken) and each detector's quality and f1, with the rooms' statuses."""

    name: str
    residual_px: float | None
    fit_px: float | None
    quality: dict[str, float | None]
    f1: dict[str, float | None]
    rooms: dict[str, int]

    def summary(self) -> dict:
        return {"residual_px": _rounded(self.residual_px), "fit_px": _rounded(self.fit_px),
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
    residual = fit = None
    if name not in BROKEN_ANNOTATIONS:
        keys = keypoint_pairs(data / "halmstad", name, building)
        residual, fit = keypoint_residual(result, map_path, *keys), fit_residual(*keys)
    return Scored(name, residual, fit,
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
        for against, key in (("pcmapq's alignment", "residual_px"), ("own fit", "fit_px")):
            known = [m for m in maps if getattr(m, key) is not None]
            rhos.append(row([building, str(len(known)), against,
                             *(_fmt(rho([getattr(m, key) for m in known],
                                        [m.quality[d] for m in known])) for d in DETECTORS)]))
        lines += [row([m.name, _fmt(m.residual_px, 1), _fmt(m.fit_px, 1),
                       *(score(m.quality[d], 2) for d in DETECTORS),
                       truth_rooms(m.rooms)])
                  for m in maps]
    return Section("\n".join([
        "## Rooms of real robot maps: Halmstad against the layouts", "",
        f"The {len(got)} Halmstad maps of four buildings (the Halmstad section's data and "
        "settings), "
        "each scored against its building's layout with `--detectors "
        f"{','.join(DETECTORS)}`. Two residuals, each the median distance, layout pixels "
        "of 0.05 m, from the annotated map keypoints to their layout keypoints: carried by "
        "pcmapq's alignment (a map bent or stretched, or placed a little off, has a larger "
        "one), and carried by their own least-squares similarity fit (the map's distortion and "
        "the annotations' noise alone, whatever pcmapq does). "
        f"{', '.join(sorted(BROKEN_ANNOTATIONS))}'s annotation is broken: no residual. rho: "
        "Spearman's rank correlation of each detector's quality with a residual over a "
        "building's maps (-1: the quality falls wherever the residual grows), maps with no "
        "residual or no quality (n/a: no truth room seen whole enough to count) left out.", "",
        header(["building", "maps", "residual", *(f"rho {d}" for d in DETECTORS)]),
        *rhos, "",
        header(["map", "residual px", "own fit px", *(f"q {d}" for d in DETECTORS),
                "truth rooms"]),
        *lines,
    ]))


def truth_rooms(counts: dict[str, int]) -> str:
    """The truth rooms' statuses of a result's room counts, e.g. "7 matched, 1 split"."""
    return ", ".join(f"{n} {k.replace('truth ', '')}" for k, n in counts.items()
                     if k.startswith("truth ") and "door" not in k)


def _rounded(value: float | None) -> float | None:
    return None if value is None else round(value, 6)


def _fmt(value: float | None, digits: int = 2) -> str:
    return "n/a" if value is None else f"{value:.{digits}f}"
