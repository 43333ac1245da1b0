"""Time and score pcmapq.align.align on synthetic cases; prints a markdown table.

Run: ``python -m bench.bench_align``. Truth: wall points of ``building_plan(0)`` (24 m x 16 m)
every 0.05 m; maps: the same walls resampled with 1.5 cm noise, cut, bent or replaced, then
turned and shifted into a map frame by a known transform. For the bent map the error is against
that transform, which no rigid fit can fully recover; the other building has no right answer.
"""

from __future__ import annotations

import resource
import time

import numpy as np

from pcmapq.align import align
from pcmapq.core.transform import Similarity2D
from testkit import synth

W, H = 24.0, 16.0


def crop(points: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """The points inside the box, metres."""
    keep = (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)
    return points[keep]


def cases() -> list[tuple[str, np.ndarray, np.ndarray, Similarity2D | None]]:
    """(name, map points in the map frame, truth points, T_true or None if there is none)."""
    plan = synth.building_plan(0)
    truth = synth.wall_points(plan, spacing=0.05)
    scan = synth.wall_points(plan, spacing=0.05, noise=0.015, seed=1)
    bent = synth.wall_points(synth.bend_segments(plan, 0.3), spacing=0.05, noise=0.015, seed=2)
    other = synth.wall_points(synth.building_plan(7, 18.0, 20.0), spacing=0.05, noise=0.015,
                              seed=3)
    cluttered = synth.wall_points(synth.clutter(plan, 40, seed=4), spacing=0.05)
    big_plan = synth.building_plan(5, 80.0, 50.0)
    big_truth = synth.wall_points(big_plan, spacing=0.05)
    big_scan = synth.wall_points(big_plan, spacing=0.05, noise=0.015, seed=1)
    rows = [(f"full, yaw {yaw}", scan, truth, True, (yaw, tx, ty))
            for yaw, tx, ty in ((15, 5, -3), (90, -20, 12), (172, 35, 40), (-47, -12, -30))]
    rows += [
        ("partial: left half (50 %)", crop(scan, -1, -1, W / 2, 17), truth, True, (33, 8, -6)),
        ("partial: top-right third (34 %)", crop(scan, 0.42 * W, 0.42 * H, 25, 17), truth, True,
         (-120, -15, 25)),
        ("partial: corner (60 %)", crop(scan, -1, -1, 0.775 * W, 0.775 * H), truth, True,
         (200, 22, 4)),
        ("partial: bottom 30 %", crop(scan, -1, -1, 25, 0.3 * H), truth, True, (71, -3, -18)),
        ("partial: right half, cluttered truth", crop(scan, W / 2, -1, 25, 17), cluttered, True,
         (140, 30, 10)),
        ("bent 0.3 deg/m", bent, truth, True, (60, 10, 5)),
        ("other building (18 m x 20 m)", other, truth, False, (30, 3, 3)),
        ("large building 80 m x 50 m", big_scan, big_truth, True, (123, 40, -70)),
    ]
    out = []
    for name, pts, tru, known, (yaw, tx, ty) in rows:
        t_true = Similarity2D(float(tx), float(ty), float(np.radians(yaw)))
        out.append((name, t_true.inverse().apply(pts), tru, t_true if known else None))
    return out


def main() -> None:
    print("| case | map pts | truth pts | yaw error (deg) | shift error (m) | fitness | "
          "RMSE (m) | seconds |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    total = 0.0
    for name, map_xy, truth, t_true in cases():
        start = time.perf_counter()
        result = align(map_xy, truth)
        seconds = time.perf_counter() - start
        total += seconds
        if t_true is None:
            yaw_err = shift_err = "-"
        else:
            tf = result.transform
            yaw_err = f"{abs((np.degrees(tf.yaw - t_true.yaw) + 180) % 360 - 180):.3f}"
            shift_err = f"{np.hypot(tf.tx - t_true.tx, tf.ty - t_true.ty):.3f}"
        print(f"| {name} | {len(map_xy)} | {len(truth)} | {yaw_err} | {shift_err} | "
              f"{result.fitness:.3f} | {result.rmse_m:.3f} | {seconds:.2f} |")
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\nAll cases: {total:.2f} s; peak RSS {peak_mb:.0f} MB.")


if __name__ == "__main__":
    main()
