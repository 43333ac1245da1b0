"""Does a score depend on how the walls are drawn? The same geometry drawn otherwise, scored
against the usual drawing in both directions (no alignment: same frame).

- synthetic: the plan of ``pcmapq.synth.building_plan`` drawn with walls 1, 2, 3 and 6 cells
  thick and as double outlines (the two faces of a 0.15 m wall, one cell each) at 0.05 m and
  0.025 m cells, against the usual drawing (0.15 m walls at 0.05 m);
- real: the Freiburg 079 SLAM map thickened by one and two cells and thinned to its skeleton,
  and a Halmstad layout against its skeleton (../shared/data);
- counts: the strong features each detector finds on every real truth of ../shared/data.

    python tools/drawings.py [--seeds 0,1,2] [--data ../shared/data] [--counts-only]
        [--figure docs/img/wall_band.png]

Prints markdown tables: per variant and detector the feature counts and quality / precision
in both directions (variant as the map, then variant as the truth); then the counts.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np
from skimage.morphology import skeletonize

from pcmapq import synth
from pcmapq.config import Settings
from pcmapq.features import detect, walls_of
from pcmapq.grid import MetricGrid
from pcmapq.io import OccupancyMap, load_map
from pcmapq.match import match
from pcmapq.pipeline import plan_points, truth_raster
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


#: Every real truth: (name, path under the data folder, metres per pixel of an image).
TRUTHS = (
    ("Gazebo world (rendered)", "gazebo/Ground_Truth.png", 1.0 / 529.0),
    ("Intel Research Lab plan", "floorplans/lab_intel.png", 0.05),
    ("Freiburg 079 plan", "floorplans/Freiburg79_scan.png", 0.05),
    *((f"Halmstad {b} layout", f"halmstad/maps/{b}/layout/{b}_layout.png", 0.05)
      for b in ("E5", "F5", "HIH", "KPT4A")),
    ("Intel CARMEN log (corrected poses)", "carmen/intel-corrected.log.gz", None),
    ("FHW CARMEN log (corrected poses)", "carmen/fhw-corrected.log.gz", None),
)


def truth_counts(data: Path) -> str:
    """A markdown table of the strong features of every real truth that is present."""
    lines = ["### Strong features of the real truths", "",
             "| truth | cells | " + " | ".join(NAMES) + " |", "|---" * (len(NAMES) + 2) + "|"]
    for title, rel, resolution in TRUTHS:
        path = data / rel
        if not path.is_file():
            continue
        source = load_map(path, resolution)
        if isinstance(source, OccupancyMap):
            occ, grid = source.state == OCCUPIED, source.grid
        else:
            grid, occ = truth_raster(source, plan_points(source, Settings())[0], Settings())
        counts = [int(detect(n, occ, grid).strong.sum()) for n in NAMES]
        lines.append(f"| {title} | {grid.shape[1]} x {grid.shape[0]} at "
                     f"{grid.resolution * 1000:.2f} mm | " + " | ".join(map(str, counts)) + " |")
    return "\n".join(lines + [""])


def figure(path: Path) -> None:
    """Save a picture of a corner of the plan drawn three ways (top) and what the detectors
    see of each (bottom), with the Harris corners."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    segments = synth.building_plan(0)
    drawings = {"1 cell at 0.025 m": None, "6 cells (0.3 m) at 0.05 m": None,
                "double outline at 0.025 m": None}
    variants = plan_variants(segments)
    keys = ("1 cell at 0.025 m", "6 cells at 0.05 m", "double outline at 0.025 m")
    fig, axes = plt.subplots(2, 3, figsize=(10, 6.4), constrained_layout=True)
    window = (11.0, 21.5, 8.0, 15.0)  # x0, x1, y0, y1 metres: rooms, a corridor, pillars
    for col, (title, key) in enumerate(zip(drawings, keys, strict=True)):
        occ, grid = variants[key]
        walls = walls_of(occ, grid)
        image, work = walls.image, walls.grid
        corners = detect("harris", occ, grid)
        for row, (img, g) in enumerate(((occ.astype(float), grid), (image, work))):
            ax = axes[row, col]
            x0, y0 = g.origin[:2]
            w, h = g.size_m
            ax.imshow(img, cmap="Greys", vmin=0, vmax=1, extent=(x0, x0 + w, y0, y0 + h),
                      interpolation="nearest")
            if row == 1:
                xy = corners.xy[corners.strong]
                ax.plot(xy[:, 0], xy[:, 1], "o", mfc="none", mec="tab:red", ms=7)
            ax.set_xlim(window[0], window[1])
            ax.set_ylim(window[2], window[3])
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(title if row == 0 else "what the detectors see", fontsize=10)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("--data", type=Path, default=DATA)
    parser.add_argument("--counts-only", action="store_true")
    parser.add_argument("--figure", type=Path, help="save the picture of docs/method.md here")
    args = parser.parse_args(argv)
    if args.figure is not None:
        figure(args.figure)
        return 0
    if args.counts_only:
        print(truth_counts(args.data))
        return 0
    for seed in (int(s) for s in args.seeds.split(",")):
        print(synthetic(seed))
    fr79 = args.data / "floorplans" / "freiburg_building79.png"
    layout = args.data / "halmstad" / "maps" / "E5" / "layout" / "E5_layout.png"
    if fr79.is_file():
        print(real(fr79, 0.05, "Freiburg 079 SLAM map (0.05 m assumed)",
                   ("thickened by 1 cell", "thickened by 2 cells", "skeleton")))
    if layout.is_file():
        print(real(layout, 0.05, "Halmstad E5 layout (0.05 m assumed)", ("skeleton",)))
    print(truth_counts(args.data))
    return 0


if __name__ == "__main__":
    sys.exit(main())
