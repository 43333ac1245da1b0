"""Time and memory of the distance transform (metres to the nearest wall cell) on a large grid:
pcmapq's ``nearest_distance`` (OpenCV's exact transform, kept in float32 cells and read in
float64 metres where it is indexed) against SciPy's ``distance_transform_edt`` in metres, and
the float32 transform alone (:func:`pcmapq.core.morphology.distance_to`).

    python -m bench.bench_distance [--size 8000] [--repeat 3]   prints a markdown table

The grid is a synthetic building plan's walls, ``size`` x ``size`` cells of 0.05 m. Each case
runs in a fresh process on the same saved raster, so its peak memory is its own: "extra MB" is
the rise of the peak RSS over the resident memory before the transform (imports and raster
loaded).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from pcmapq.core.grid import MetricGrid
from testkit import synth

RESOLUTION = 0.05

CHILD = r"""
import json, resource, sys, time
import numpy as np
from scipy import ndimage
from pcmapq.core.grid import MetricGrid
from pcmapq.metrics.distances import nearest_distance
from pcmapq.core.morphology import distance_to

case, path, repeat, res = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
walls = np.load(path)
grid = MetricGrid(res, (0.0, 0.0, 0.0), walls.shape)
run = {"scipy": lambda: ndimage.distance_transform_edt(~walls) * res,
       "pcmapq": lambda: nearest_distance(walls, grid),
       "distance_to": lambda: distance_to(walls)}
with open("/proc/self/statm") as f:  # resident pages now, not the peak of the imports
    before = int(f.read().split()[1]) * resource.getpagesize() / 1024
if case == "difference":
    scipy, ours = run["scipy"](), run["pcmapq"]()[...]
    print(json.dumps({"max_m": float(np.abs(scipy - ours).max()),
                      "max_rel": float((np.abs(scipy - ours) / np.maximum(scipy, res)).max()),
                      "farthest_m": float(scipy.max())}))
    sys.exit()
seconds = []
for _ in range(repeat):
    t0 = time.perf_counter()
    out = run[case]()
    seconds.append(time.perf_counter() - t0)
    del out
extra = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
print(json.dumps({"case": case, "seconds": min(seconds), "extra_mb": extra}))
"""


def walls_raster(size: int) -> np.ndarray:
    """The walls (bool, size x size) of a synthetic building plan filling the grid."""
    side = size * RESOLUTION - 2.0  # plan_grid's 1 m margin on each side
    plan = synth.building_plan(seed=1, width=side, height=side)
    grid = MetricGrid(RESOLUTION, (-1.0, -1.0, 0.0), (size, size))
    return synth.render(plan, grid) == synth.OCCUPIED


def child(*args: str) -> dict:
    proc = subprocess.run([sys.executable, "-c", CHILD, *args], capture_output=True, text=True,
                          check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=8000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = str(Path(tmp) / "walls.npy")
        walls = walls_raster(args.size)
        np.save(path, walls)
        common = [path, str(args.repeat), str(RESOLUTION)]
        rows = [child(case, *common) for case in ("scipy", "pcmapq", "distance_to")]
        diff = child("difference", *common)
    print(f"{args.size} x {args.size} cells, {walls.mean():.2%} walls, farthest cell "
          f"{diff['farthest_m']:.1f} m; max |pcmapq - scipy| {diff['max_m']:.2g} m "
          f"(relative {diff['max_rel']:.2g}); best of {args.repeat}")
    names = {"scipy": "SciPy `distance_transform_edt` x resolution (float64)",
             "pcmapq": "`nearest_distance` (float32 cells, read in metres)",
             "distance_to": "`morphology.distance_to` alone (float32 cells)"}
    print("| transform | seconds | extra MB |")
    print("|---|---:|---:|")
    for r in rows:
        print(f"| {names[r['case']]} | {r['seconds']:.2f} | {r['extra_mb']:.0f} |")


if __name__ == "__main__":
    main()
