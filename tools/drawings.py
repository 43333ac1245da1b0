"""Does a score depend on how the walls are drawn? The same geometry drawn otherwise, scored
against the usual drawing in both directions (no alignment: same frame).

- synthetic: the plan of ``pcmapq.synth.building_plan`` drawn with walls 1, 2, 3 and 6 cells
  thick and as double outlines (the two faces of a 0.15 m wall, one cell each) at 0.05 m and
  0.025 m cells, against the usual drawing (0.15 m walls at 0.05 m);
- real: the Freiburg 079 SLAM map thickened by one and two cells and thinned to its skeleton,
  and a Halmstad layout against its skeleton (../shared/data).

    python tools/drawings.py [--seeds 0,1,2] [--data ../shared/data]

Prints markdown tables: per variant and detector the feature counts and quality / precision
in both directions (variant as the map, then variant as the truth).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np
from skimage.morphology import skeletonize

from pcmapq import synth
from pcmapq.features import detect
from pcmapq.grid import MetricGrid
from pcmapq.io import load_map
from pcmapq.match import match
from pcmapq.raster.draw import OCCUPIED

NAMES = ("harris", "hough", "sift")
DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
#: The usual drawing: walls 0.15 m thick on 0.05 m cells.
USUAL_RESOLUTION, USUAL_THICKNESS = 0.05, 0.15


def thicken(occupied: np.ndarray, cells: int) -> np.ndarray:
    """The occupied cells grown by ``cells`` cells (square structuring element)."""
    kernel = np.ones((2 * cells + 1, 2 * cells + 1), np.uint8)
    return cv2.dilate(occupied.astype(np.uint8), kernel) > 0


def plan_variants(segments: np.ndarray) -> dict[str, tuple[np.ndarray, MetricGrid]]:
    """The plan's drawings by name: ``(occupied, grid)``."""
    out = {}
    for res in (0.05, 0.025):
        grid = synth.plan_grid(segments, res)
        for cells in (1, 2, 3, 6):
            occ = synth.render(segments, grid, thickness=cells * res) == synth.OCCUPIED
            out[f"{cells} cell{'s' if cells > 1 else ''} at {res} m"] = occ, grid
        full = synth.render(segments, grid, thickness=USUAL_THICKNESS) == synth.OCCUPIED
        out[f"double outline at {res} m"] = synth.faces(full), grid
    return out


def both_ways(usual: dict, occ: np.ndarray, grid: MetricGrid) -> dict[str, tuple]:
    """Per detector: (variant features, q, p with the variant as map, q, p as truth)."""
    out = {}
    for name in NAMES:
        f = detect(name, occ, grid)
        a, b = match(name, usual[name], f), match(name, f, usual[name])
        out[name] = (int(f.strong.sum()), a.quality, a.precision, b.quality, b.precision)
    return out


def table(title: str, usual: dict, rows: dict[str, dict]) -> str:
    """One markdown table: the usual drawing's counts, then a row per variant."""
    head = " | ".join(f"{n} n, q / p (map), q / p (truth)" for n in NAMES)
    lines = [f"### {title}", "", f"| drawing | {head} |", "|---" * (len(NAMES) + 1) + "|",
             "| usual | " + " | ".join(f"{int(usual[n].strong.sum())}" for n in NAMES) + " |"]
    worst = 1.0
    for label, row in rows.items():
        cells = []
        for n in NAMES:
            count, *scores = row[n]
            worst = min(worst, *scores)
            cells.append(f"{count}, {scores[0]:.2f} / {scores[1]:.2f}, "
                         f"{scores[2]:.2f} / {scores[3]:.2f}")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines + ["", f"Lowest quality or precision: {worst:.2f}", ""])


def synthetic(seed: int) -> str:
    segments = synth.building_plan(seed)
    grid = synth.plan_grid(segments, USUAL_RESOLUTION)
    occ = synth.render(segments, grid, thickness=USUAL_THICKNESS) == synth.OCCUPIED
    usual = {n: detect(n, occ, grid) for n in NAMES}
    rows = {label: both_ways(usual, o, g) for label, (o, g) in plan_variants(segments).items()}
    return table(f"Synthetic plan, seed {seed}", usual, rows)


def real(path: Path, resolution: float, title: str, variants: tuple[str, ...]) -> str:
    source = load_map(path, resolution)
    occ, grid = source.state == OCCUPIED, source.grid
    usual = {n: detect(n, occ, grid) for n in NAMES}
    made = {"thickened by 1 cell": lambda: thicken(occ, 1),
            "thickened by 2 cells": lambda: thicken(occ, 2),
            "skeleton": lambda: skeletonize(occ)}
    rows = {v: both_ways(usual, made[v](), grid) for v in variants}
    return table(title, usual, rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("--data", type=Path, default=DATA)
    args = parser.parse_args(argv)
    for seed in (int(s) for s in args.seeds.split(",")):
        print(synthetic(seed))
    fr79 = args.data / "floorplans" / "freiburg_building79.png"
    layout = args.data / "halmstad" / "maps" / "E5" / "layout" / "E5_layout.png"
    if fr79.is_file():
        print(real(fr79, 0.05, "Freiburg 079 SLAM map (0.05 m assumed)",
                   ("thickened by 1 cell", "thickened by 2 cells", "skeleton")))
    if layout.is_file():
        print(real(layout, 0.05, "Halmstad E5 layout (0.05 m assumed)", ("skeleton",)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
