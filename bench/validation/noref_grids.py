"""No-reference grid figures of the real 2D maps beside their truths (part of the ``noref``
section): each SLAM map of the Gazebo, Halmstad and floor-plan sections and its truth scored by
:func:`pcmapq.metrics.noref2d.grid_scores`, the map at the pixel size the evaluation estimates
(truth cell x scale), beside the qualities the map gets against its truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

from pcmapq.report.text import number, score
from testkit.realdata import halmstad
from testkit.realdata.noref_grids import Scored, pairs, score_pair

from .common import Case, header, row

#: The figures of the table, as (label, key) of a :func:`grid_figures` record.
FIGURES = (("occupied", "occupied_cells"), ("free", "free_cells"),
           ("occ/free", "occupied_free_ratio"), ("corners", "corners"),
           ("enclosed", "enclosed_areas"), ("enclosed m²", "enclosed_area_m2"),
           ("largest m²", "largest_enclosed_m2"))
DETECTORS = ("harris", "hough", "sift")


def cases(data: Path) -> list[Case]:
    return [Case(p.case, lambda p=p: score_pair(p)) for p in pairs(data)]


def cell(value: float | int | None) -> str:
    """A figure of the table: integers with separators, ratios 3 decimals, areas 1."""
    if value is None:
        return "-"
    if isinstance(value, int):
        return f"{value:,}"
    if value == 0:
        return "0"
    return f"{value:.3f}" if value < 1 else f"{value:.1f}"


def table(scored: list[Scored]) -> list[str]:
    """Two rows a pair: the map (with its qualities against the truth), then the truth."""
    lines = [header(["pair", "image", "cell mm", *[label for label, _ in FIGURES],
                     *[f"q {d}" for d in DETECTORS], "acc mean m"])]
    for s in scored:
        r = s.run.result
        q = [score(r.detectors[d].matching.quality, 2) for d in DETECTORS]
        for image, figures, tail in (("map", s.map, [*q, number(r.distances.accuracy.mean)]),
                                     ("truth", s.truth, ["-"] * (len(DETECTORS) + 1))):
            how = "scale" if image == "map" else s.pair.resolution_note
            lines.append(row([s.pair.label if image == "map" else "", image,
                              f"{1000 * figures['resolution_m']:.2f} ({how})",
                              *[cell(figures[key]) for _, key in FIGURES], *tail]))
    return lines


def rho(x: list[float], y: list[float]) -> tuple[float, float]:
    """Spearman's rank correlation and its p-value (NaN when undefined)."""
    found = spearmanr(x, y)
    return float(found.statistic), float(found.pvalue)


def rho_text(found: tuple[float, float]) -> str:
    return "-" if np.isnan(found[0]) else f"{found[0]:.2f} (p = {found[1]:.2f})"


def across(scored: list[Scored]) -> str:
    """How the maps' figures rank with their figures against the truth, across places."""
    maps = [s for s in scored if s.run.result.distances.accuracy.mean is not None]
    acc = [s.run.result.distances.accuracy.mean for s in maps]
    mean_q = [float(np.mean([s.run.result.detectors[d].matching.quality or 0
                             for d in DETECTORS])) for s in maps]
    found = {label: (rho([s.map[key] for s in maps], acc), rho([s.map[key] for s in maps], mean_q))
             for label, key in FIGURES if key in ("occupied_free_ratio", "corners")}
    rhos = "; ".join(f"{label} {rho_text(a)} with the accuracy, {rho_text(b)} with the mean "
                     "quality" for label, (a, b) in found.items())
    significant = [label for label, pair in found.items() for r in pair if r[1] < 0.05]
    return (
        f"Across places: Spearman's rho, over these {len(maps)} maps, of a map's figure with "
        f"its figures against its truth: {rhos}. A figure that tracked quality would have rho "
        "+1 with the accuracy (lower is better) and -1 with the mean quality (of Harris, Hough "
        "and SIFT); "
        + (f"only {', '.join(sorted(set(significant)))} reach p < 0.05" if significant else
           "none is significant at p < 0.05")
        + ". The maps are of different places, at different and partly assumed cell sizes, "
        "against truths drawn by different conventions: the figures measure the place and the "
        "drawing as much as the map, and the accuracy counts the clutter a plan leaves out as "
        "error too. Across places they are no evidence of quality; they compare maps of the "
        "same place (the CARMEN ladders above).")


def enclosed_text(scored: list[Scored]) -> str:
    """Which images enclose no area, and the Gazebo interior at the estimated pixel size."""
    open_ = [(s.pair.label, image) for s in scored
             for image, figures in (("map", s.map), ("truth", s.truth))
             if figures["enclosed_areas"] == 0]
    both = [s.pair.label for s in scored
            if (s.pair.label, "map") in open_ and (s.pair.label, "truth") in open_]
    named = [f"both images of {', '.join(both)}"] if both else []
    named += [f"the {label} {image}" for label, image in open_ if label not in both]
    text = (f"{len(open_)} of {2 * len(scored)} images enclose no area ({'; '.join(named)}): "
            "their free space touches unknown cells (a drawing's anti-aliased wall edges or "
            "grey wall fill read unknown, a map's free space reaches its unexplored part), so "
            "the enclosed areas say something only of maps whose free space is closed.")
    gz = scored[0]
    if gz.map["largest_enclosed_m2"] and gz.truth["largest_enclosed_m2"]:
        gap = gz.map["largest_enclosed_m2"] / gz.truth["largest_enclosed_m2"] - 1
        text += (" The Gazebo pair's is: the map's largest enclosed area (the building's "
                 f"interior) differs from the truth's by {100 * gap:+.1f} % in square metres at "
                 f"the estimated pixel size ({1 / gz.run.result.transform.scale ** 2:.2f} of it at "
                 "the truth's cell size).")
    return text


def section_lines(scored: list[Scored]) -> list[str]:
    """The subsection: what was scored, the table, and what it shows."""
    more = [s.map["occupied_free_ratio"] / s.truth["occupied_free_ratio"] for s in scored]
    larger = sum(m > 1 for m in more)
    corners = sum(s.map["corners"] >= s.truth["corners"] for s in scored)
    gz = scored[0]
    return [
        "### 2D: real maps beside their truths", "",
        "The SLAM maps of the Gazebo, Halmstad (one map per building) and floor-plan sections "
        "and their truths, each image scored by `pcmapq.metrics.noref2d.grid_scores` (as "
        "`pcmapq inspect` scores an image; `bench/validation/noref_grids.py`), beside the "
        "map's qualities and mean accuracy against its truth (the same evaluations as in those "
        "sections). No map gives its pixel size: each is scored at the truth's cell times the "
        "scale the evaluation estimates ('scale'; the Gazebo map at "
        f"{1000 * gz.truth['resolution_m']:.3f} mm x {gz.run.result.transform.scale:.4f} = "
        f"{1000 * gz.map['resolution_m']:.3f} mm). The Gazebo truth's cell is given (529 px "
        "per metre); the Halmstad layouts and floor plans are taken at "
        f"{halmstad.PLAN_RESOLUTION:g} m per pixel ('assumed'), so their areas are square "
        "metres only under that assumption. Largest m²: the largest enclosed area.", "",
        *table(scored), "",
        f"Against its own truth, {larger} of {len(scored)} maps have a larger occupied/free "
        f"ratio ({min(more):.1f} to {max(more):.1f} times the truth's) and {corners} of "
        f"{len(scored)} at least as many corners: a SLAM map's walls are thicker than a "
        "drawing's and it holds furniture and clutter a plan leaves out, so the truth's "
        "figures are those of a drawing, not what a perfect SLAM map of the place would score. "
        + enclosed_text(scored), "",
        across(scored),
    ]
