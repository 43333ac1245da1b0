"""Align every Halmstad robot map to its building's layout with unknown scale; prints a markdown
table and the share of maps whose annotated keypoints land within 20 px (median) of their layout
partners.

Run: ``python -m bench.bench_scale [DATA]`` (DATA defaults to ``../shared/data/halmstad``).
Both images are read in pixels (x = column, y = rows - 1 - row, the annotations' frame); the
reference is the least-squares similarity fitted to the annotated keypoint pairs. E5_08 is
skipped: its annotation is broken (reference median residual 34 px).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import cv2
import numpy as np

from pcmapq.align import AlignParams, align
from pcmapq.align.similarity_icp import fit_similarity
from pcmapq.core.transform import Similarity2D
from testkit.realdata.halmstad import BROKEN_ANNOTATIONS, keypoint_pairs

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "halmstad"
TARGET_PX = 20.0
#: Share of the maps that should be under TARGET_PX.
TARGET_SHARE = 0.8
#: Alignment in pixel units: 1 px voxels, 4 px inlier tolerance.
PIXELS = AlignParams(tolerance=4.0, voxel=1.0)
#: A layout's walls: pixels darker than this grey.
WALL_GREY = 100


def occupied_pixels(mask: np.ndarray) -> np.ndarray:
    """Centres (N, 2) of the true pixels, x = column, y = rows - 1 - row."""
    v, u = np.nonzero(mask)
    return np.column_stack([u, mask.shape[0] - 1 - v]).astype(np.float64)


def run(data: Path) -> list[tuple[str, Similarity2D, Similarity2D, float, float]]:
    """(map, reference, pcmapq's similarity, median keypoint residual px, seconds) per map."""
    rows = []
    for path in sorted(data.glob("maps/*/pseudo_occupancy/*.png")):
        name, building = path.stem, path.parents[1].name
        if name in BROKEN_ANNOTATIONS:
            continue
        layout = cv2.imread(str(data / "maps" / building / "layout" / f"{building}_layout.png"),
                            cv2.IMREAD_UNCHANGED)
        truth_xy = occupied_pixels(layout[..., :3].mean(axis=2) < WALL_GREY)
        map_xy = occupied_pixels(cv2.imread(str(path), cv2.IMREAD_GRAYSCALE) == 0)
        map_keys, layout_keys = keypoint_pairs(data, name, building)
        start = time.perf_counter()
        got = align(map_xy, truth_xy, PIXELS, scale=True).transform
        seconds = time.perf_counter() - start
        residual = np.linalg.norm(got.apply(map_keys) - layout_keys, axis=1)
        rows.append((name, fit_similarity(map_keys, layout_keys), got,
                     float(np.median(residual)), seconds))
        print(f"{name}: {rows[-1][3]:.1f} px, {seconds:.1f} s", file=sys.stderr)
    return rows


def main() -> None:
    data = Path(sys.argv[1]) if len(sys.argv) > 1 else DATA
    rows = run(data)
    print("| map | reference scale | reference rotation (deg) | pcmapq scale | "
          "pcmapq rotation (deg) | median keypoint residual (px) | seconds |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, ref, got, residual, seconds in rows:
        print(f"| {name} | {ref.scale:.3f} | {ref.yaw_deg:.1f} | {got.scale:.3f} | "
              f"{got.yaw_deg:.1f} | {residual:.1f} | {seconds:.1f} |")
    good = sum(r[3] < TARGET_PX for r in rows)
    share = good / max(len(rows), 1)
    print(f"\n{good} of {len(rows)} maps ({share:.0%}) under {TARGET_PX:.0f} px; "
          f"median {np.median([r[4] for r in rows]):.1f} s a map.")


if __name__ == "__main__":
    main()
