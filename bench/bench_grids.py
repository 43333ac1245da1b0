"""Time and peak memory of `pcmapq eval MAP.yaml TRUTH.yaml` on large grids (issue 10, parts 1
and 5), each beside its floor: OpenCV reading both images and one exact distance transform of the
truth's walls (the least any comparison of two grids does), measured in the same run.

    python -m bench.bench_grids [--sizes 1000,2000,4000,8000] [--tmp DIR]

Each case is :mod:`bench.large_grid`'s: a campus of copies of one building, ``size`` x ``size``
cells of 0.05 m for the truth and for the map (turned -12 degrees, moved, walls from points with
3 cm noise), written into a temporary folder and deleted after. Every run is a fresh process,
its peak GB the child's peak memory (:func:`bench.bench_clouds.measured`); pcmapq s is the
whole process's wall time, floor s the floor's work timed inside its process. The pose error
is against the known transform.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import sys
import tempfile
from pathlib import Path

from bench import large_grid
from bench.bench_clouds import measured
from pcmapq.core.transform import Similarity2D

FLOOR_CHILD = r"""
import json, sys, time
import cv2
start = time.perf_counter()
truth = cv2.imread(sys.argv[1], cv2.IMREAD_GRAYSCALE)
map_ = cv2.imread(sys.argv[2], cv2.IMREAD_GRAYSCALE)
cv2.distanceTransform((truth != 0).view("uint8"), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
print(json.dumps({"seconds": time.perf_counter() - start}))
"""


def grid_row(size: int, tmp: Path) -> dict:
    """Generate one case, run the floor and pcmapq on it, delete it."""
    case = tmp / f"grid_{size}"
    try:
        known = large_grid.write_case(case, size)
        _, floor_gb, text = measured([sys.executable, "-c", FLOOR_CHILD,
                                      str(case / "truth.png"), str(case / "map.png")])
        result = case / "result.json"
        seconds, gb, _ = measured([sys.executable, "-m", "pcmapq", "eval", str(case / "map.yaml"),
                                   str(case / "truth.yaml"), "--json", str(result)])
        got = json.loads(result.read_text())
        error = known.inverse().compose(Similarity2D.from_dict(got["alignment"]))
        return {"size": size, "s": seconds, "gb": gb,
                "floor_s": json.loads(text.strip().splitlines()[-1])["seconds"],
                "floor_gb": floor_gb, "error_m": math.hypot(error.tx, error.ty),
                "error_deg": abs(error.yaw_deg),
                "quality": "/".join(f"{d['quality']:.3f}" for d in got["detectors"].values())}
    finally:
        shutil.rmtree(case, ignore_errors=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1000,2000,4000,8000")
    parser.add_argument("--tmp", type=Path, default=None)
    args = parser.parse_args()
    print("| cells | metres | pcmapq s | pcmapq GB | floor s | floor GB | ratio | pose error "
          "(m / deg) | quality harris/hough/sift |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    with tempfile.TemporaryDirectory(dir=args.tmp) as tmp:
        for size in (int(s) for s in args.sizes.split(",")):
            r = grid_row(size, Path(tmp))
            print(f"| {size}^2 | {size * large_grid.RESOLUTION:.0f} | {r['s']:.1f} | "
                  f"{r['gb']:.2f} | {r['floor_s']:.2f} | {r['floor_gb']:.2f} | "
                  f"{r['s'] / r['floor_s']:.0f} | {r['error_m']:.3f} / {r['error_deg']:.3f} | "
                  f"{r['quality']} |", flush=True)


if __name__ == "__main__":
    main()
