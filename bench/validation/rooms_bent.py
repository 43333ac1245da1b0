"""Rooms of bent real maps: a Halmstad map per building bent more and more (the slow turn that
odometry drift gives a map, :func:`pcmapq.testing.synth.bend_image`) and scored against its
building's layout: does the rooms' quality fall with the bend, as on the CARMEN ladders?"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import cv2

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.report.text import score
from pcmapq.results.result import SAME
from pcmapq.testing import synth
from pcmapq.testing.realdata.halmstad import halmstad_truth, paths

from .common import Case, Record, Section, header, row
from .noref import rho
from .rooms_drift import RHO, rho_cell
from .rooms_halmstad import DETECTORS, ROOMS_SETTINGS, truth_rooms

#: Each building's map with the most truth rooms matched in the Halmstad rooms section (the
#: first by name among equals): a map with rooms to lose.
MAPS = ("E5_07", "F5_12", "HIH_01", "KPT4A_01")
#: How far the bend moves the far corner of the map's known pixels, a share of their box's
#: diagonal (on these maps 1 % is about 0.4-0.6 m).
LEVELS = (0.0, 0.01, 0.02, 0.04, 0.08)
#: The maps' unknown grey.
UNKNOWN = 127
#: The Halmstad rooms settings, forced: a bent map the verdict refuses is scored all the same,
#: and the verdict shown.
SETTINGS = replace(ROOMS_SETTINGS, alignment=replace(ROOMS_SETTINGS.alignment, force=True))


@dataclass(frozen=True)
class Bent:
    """One map at one bend: the scale and the verdict of its alignment, each detector's quality
    and the rooms' statuses."""

    name: str
    level: float
    scale: float
    verdict: str
    quality: dict[str, float | None]
    rooms: dict[str, int]

    def summary(self) -> dict:
        return {"scale": round(self.scale, 6), "verdict": self.verdict,
                "quality": {k: None if v is None else round(v, 6)
                            for k, v in self.quality.items()},
                "rooms": self.rooms}


def bent(name: str, level: float, data: Path) -> Bent:
    """The map bent by ``level`` and scored against its layout with the four detectors."""
    map_path, layout = paths(data, name)
    image = cv2.imread(str(map_path), cv2.IMREAD_UNCHANGED)
    with tempfile.TemporaryDirectory(prefix="pcmapq_halmstad_bent_") as tmp:
        drawn = Path(tmp) / f"{name}.png"
        cv2.imwrite(str(drawn), synth.bend_image(image, level, UNKNOWN))
        result = evaluate(drawn, halmstad_truth(layout, Path(tmp)), SETTINGS)
    return Bent(name, level, result.alignment.transform.scale, result.overlap.verdict,
                {k: d.matching.quality for k, d in result.detectors.items()},
                result.rooms["counts"] if result.rooms else {})


def cases(data: Path) -> list[Case]:
    return [Case(f"halmstad-rooms-bent-{name}-{100 * level:g}",
                 lambda name=name, level=level: bent(name, level, data))
            for name in MAPS for level in LEVELS]


def section(data: Path, record: Record) -> Section:
    """Per map: each detector's quality at each bend, and its rank correlation with the bend."""
    got = [case.run(record) for case in cases(data)]
    lines = []
    for i, name in enumerate(MAPS):
        ladder = got[i * len(LEVELS):(i + 1) * len(LEVELS)]
        lines += [row([name if k == 0 else "", f"{100 * b.level:g}", f"{b.scale:.3f}",
                       b.verdict if b.verdict == SAME else f"**{b.verdict}**",
                       *(score(b.quality[d], 2) for d in DETECTORS), truth_rooms(b.rooms)])
                  for k, b in enumerate(ladder)]
        falls = [rho_cell(rho(list(LEVELS), [b.quality[d] for b in ladder])) for d in DETECTORS]
        lines.append(row(["", "rho", "", "", *falls, ""]))
    return Section("\n".join([
        "## Rooms of bent real maps: Halmstad maps bent more and more", "",
        "The Halmstad maps do not span a range of drift (their keypoints' own fit residuals, "
        "above, are the annotations' noise), so drift is put into them: each building's map "
        "with the most truth rooms matched above, bent about the lower-left corner of its "
        "known pixels by an angle growing along x (`synth.bend_image`, the turn that odometry "
        "drift gives a map, as `synth.bend` bends the synthetic plans) so that the far corner "
        "moves by the given share of the known box's diagonal, then scored against its "
        "layout as above (scale unknown), with `force`: scale is the scale the alignment "
        "found; verdict in bold where it is not the same place. rho: Spearman's rank "
        "correlation of the quality with the bend, "
        f"over the {len(LEVELS)} levels (n/a: no quality, or all equal); bold where above "
        f"{RHO}.", "",
        header(["map", "bend % of diagonal", "scale", "verdict", *(f"q {d}" for d in DETECTORS),
                "truth rooms"]),
        *lines,
    ]))
