"""Rooms of bent real maps: a Halmstad map per building bent more and more (the slow turn that
odometry drift gives a map, :func:`testkit.synth.bend_image`), each way and from each
side, and scored against its building's layout: does the rooms' quality fall with the bend, as
on the CARMEN ladders?"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from pcmapq.evaluation.pipeline import evaluate
from pcmapq.evaluation.same_place import RECALL_NONE, STANDS_OUT
from pcmapq.report.text import score
from pcmapq.results.result import INCONSISTENT, OTHER
from testkit import synth
from testkit.realdata.halmstad import halmstad_truth, paths

from .common import Case, Record, Section, header, row
from .rooms_drift import RHO, rho, rho_cell
from .rooms_halmstad import DETECTORS, ROOMS_SETTINGS, truth_rooms

#: Each building's map with the most truth rooms matched in the Halmstad rooms section (the
#: first by name among equals): a map with rooms to lose.
MAPS = ("E5_07", "F5_12", "HIH_01", "KPT4A_01")
#: How far the bend moves the far corner of the map's known pixels, a share of their box's
#: diagonal (on these maps 1 % is about 0.4-0.6 m): from a map a little off to one bent as
#: much as the CARMEN ladders' last levels drift (several metres).
LEVELS = (0.0, 0.01, 0.02, 0.04, 0.08, 0.16, 0.32)
#: A quality "holds" while its mean over the draws stays within this of the unbent map's.
HOLDS = 0.05
#: The draws of every bend above 0: the map turned by k quarter turns, bent one way (+1) or the
#: other (-1), and turned back, so that the bend grows along each side of the map in turn. The
#: first is the bend alone.
DRAWS = tuple((turns, way) for turns in range(4) for way in (1, -1))
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
    draw: int
    scale: float
    verdict: str
    quality: dict[str, float | None]
    rooms: dict[str, int]
    iou: float | None

    def summary(self) -> dict:
        return {"scale": round(self.scale, 6), "verdict": self.verdict,
                "quality": {k: None if v is None else round(v, 6)
                            for k, v in self.quality.items()},
                "rooms": self.rooms, "iou": None if self.iou is None else round(self.iou, 6)}


def bent_image(image: np.ndarray, level: float, draw: int) -> np.ndarray:
    """``image`` bent by ``level`` as draw ``draw`` of DRAWS bends it."""
    turns, way = DRAWS[draw]
    turned = np.ascontiguousarray(np.rot90(image, turns))
    return np.ascontiguousarray(np.rot90(synth.bend_image(turned, way * level, UNKNOWN), -turns))


def bent(name: str, level: float, draw: int, data: Path) -> Bent:
    """The map bent by ``level`` (draw ``draw``) and scored against its layout with the four
    detectors."""
    map_path, layout = paths(data, name)
    image = cv2.imread(str(map_path), cv2.IMREAD_UNCHANGED)
    with tempfile.TemporaryDirectory(prefix="pcmapq_halmstad_bent_") as tmp:
        drawn = Path(tmp) / f"{name}.png"
        cv2.imwrite(str(drawn), bent_image(image, level, draw))
        result = evaluate(drawn, halmstad_truth(layout, Path(tmp)), SETTINGS)
    matched = [r["iou"] for r in (result.rooms or {}).get("truth", [])
               if r["status"] == "matched"]
    return Bent(name, level, draw, result.alignment.transform.scale, result.overlap.verdict,
                {k: d.matching.quality for k, d in result.detectors.items()},
                result.rooms["counts"] if result.rooms else {},
                float(np.mean(matched)) if matched else None)


def draws(level: float) -> range:
    """The draws of a level: one for the map unbent."""
    return range(1 if level == 0 else len(DRAWS))


def cases(data: Path) -> list[Case]:
    return [Case(f"halmstad-rooms-bent-{name}-{100 * level:g}" + (f"-draw{k}" if k else ""),
                 lambda name=name, level=level, k=k: bent(name, level, k, data))
            for name in MAPS for level in LEVELS for k in draws(level)]


def section(data: Path, record: Record) -> Section:
    """Per map and bend: each detector's quality averaged over the draws, and its rank
    correlation with the bend."""
    got = [case.run(record) for case in cases(data)]
    lines, holds = [], []
    for name in MAPS:
        means = []
        for level in LEVELS:
            runs = [b for b in got if b.name == name and b.level == level]
            mean = {d: float(np.mean([b.quality[d] or 0.0 for b in runs])) for d in DETECTORS}
            fits = [b.iou for b in runs if b.iou is not None]
            mean["iou"] = float(np.mean(fits)) if fits else float("nan")
            means.append(mean)
            scored = sum(b.verdict != OTHER for b in runs)
            inconsistent = sum(b.verdict == INCONSISTENT for b in runs)
            scales = [b.scale for b in runs]
            lines.append(row([
                name if level == 0 else "", f"{100 * level:g}", str(len(runs)),
                f"{min(scales):.3f}" + ("" if len(runs) == 1 else f"-{max(scales):.3f}"),
                (f"{scored}" if scored == len(runs) else f"**{scored}**")
                + (f" ({inconsistent} inconsistent)" if inconsistent else ""),
                *(score(mean[d], 2) for d in DETECTORS),
                "n/a" if np.isnan(mean["iou"]) else f"{mean['iou']:.3f}",
                truth_rooms(runs[0].rooms)]))
        falls = [rho_cell(rho(list(LEVELS), [m[d] for m in means]))
                 for d in (*DETECTORS, "iou")]
        lines.append(row(["", "rho", "", "", "", *falls, ""]))
        holds.append(f"{name} {_holds([m['rooms'] for m in means])}")
    return Section("\n".join([
        "## Rooms of bent real maps: Halmstad maps bent more and more", "",
        "The Halmstad maps do not span a range of drift (their keypoints' own fit residuals, "
        "above, are the annotations' noise), so drift is put into them: each building's map "
        "with the most truth rooms matched above, bent about a corner of its known pixels by "
        "an angle growing along one side (`synth.bend_image`, the turn that odometry drift "
        "gives a map, as `synth.bend` bends the synthetic plans) so that the far corner moves "
        "by the given share of the known box's diagonal, then scored against its layout as "
        f"above (scale unknown), with `force`. Each bend above 0 is drawn {len(DRAWS)} times: "
        "bent one way and the other along each of the map's four sides in turn (the map "
        "turned by quarter turns before the bend and back after). q: each detector's quality "
        "averaged over the draws (an undefined quality counts as 0); scale: the scales the "
        "alignment found; scored: the draws the verdict scores (the same place, or the same "
        "place with an inconsistent map: at least 3 of its 8 parts, placed on their own, "
        f"agree with its pose, or its pose stands out by a distinctiveness of at least "
        f"{STANDS_OUT} with a truth recall above {RECALL_NONE}), "
        "bold where not all, and how many of them it finds "
        "inconsistent; rooms IoU: the mean IoU of the matched truth rooms over the draws (how "
        "well the rooms the map still has right fit); truth rooms: the statuses of the first "
        "draw's. rho: Spearman's rank correlation of the mean quality (or IoU) with the bend, "
        f"over the {len(LEVELS)} levels; bold where above {RHO}, and n/a where the figure is "
        "the same at every level.", "",
        header(["map", "bend % of diagonal", "draws", "scale", "scored",
                *(f"q {d}" for d in DETECTORS), "rooms IoU", "truth rooms (first draw)"]),
        *lines, "",
        f"The largest bend up to which the rooms' mean quality stays within {HOLDS} of the "
        f"unbent map's: {'; '.join(holds)} (% of the diagonal).",
    ]))


def _holds(quality: list[float]) -> str:
    """The largest level (in %) up to which every mean ``quality`` (one per level of LEVELS)
    stays within HOLDS of the first."""
    ok = np.abs(np.asarray(quality) - quality[0]) <= HOLDS
    last = len(ok) if ok.all() else int(np.argmin(ok))
    return f"{100 * LEVELS[last - 1]:g}"
