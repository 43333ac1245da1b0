"""MapEval's AWD and SCS (``pcmapq.metrics.map_gaussians``): their time and peak memory beside
the 3D distances' (``distances_3d``) on one pair of clouds, and their values on KITTI 00's
pitch ladder.

    python -m bench.bench_map_gaussians [--points 1000000] [--ladder] [--voxel-3d 0.5]

Cost: the pair is bench_clouds' synthetic campus sampled twice (seeds 1 and 2, ``--points``
points each); each figure runs in a fresh process (best of three runs; peak memory: the growth
of the process's peak RSS during the first run, over its RSS before it, the pair loaded).

``--ladder``: the truth map of KITTI 00's scans at their reference poses and maps whose scan k
is pitched by k times 0.05, 0.1, 0.2 and 0.4 degrees (``testkit.kitti.pitch_ladder``), 0.1 m
voxel centroids; the time of AWD+SCS and of distances_3d on the 0.1 degree rung (in this
process, best of three); AWD and SCS of each rung against the truth in the frame given and
after pcmapq's 3D registration (``align_3d`` at ``--voxel-3d``), and in the frame given with
MapEval's own arithmetic (``testkit.mapeval.mapeval_as_coded``).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, sys, time
sys.path[:0] = [sys.argv[1]]
from bench.bench_clouds import campus_cloud
from pcmapq.metrics.distances import distances_3d
from pcmapq.metrics.map_gaussians import map_gaussians

def status(key):
    for line in open("/proc/self/status"):
        if line.startswith(key):
            return int(line.split()[1]) * 1024

kind, points = sys.argv[2], int(sys.argv[3])
a, b = campus_cloud(points, seed=1), campus_cloud(points, seed=2)
run = map_gaussians if kind == "awd" else distances_3d
run(a[:20000], b[:20000])  # compiled code and imports loaded before the measure
open("/proc/self/clear_refs", "w").write("5")  # the peak RSS restarts from here
before = status("VmRSS")
seconds = []
for _ in range(3):
    start = time.perf_counter()
    run(a, b)
    seconds.append(time.perf_counter() - start)
    if len(seconds) == 1:
        peak = status("VmHWM") - before
print(json.dumps({"seconds": min(seconds), "peak_mb": peak / 1e6}))
"""


def measured(kind: str, points: int) -> dict:
    """``kind`` ("awd": AWD and SCS; "d3": distances_3d) on the pair, in a fresh process."""
    proc = subprocess.run([sys.executable, "-c", CHILD, str(ROOT), kind, str(points)],
                          capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.splitlines()[-1])


def cost(points: int) -> None:
    awd, d3 = measured("awd", points), measured("d3", points)
    print(f"{points:,} points a cloud: AWD+SCS {awd['seconds']:.2f} s, "
          f"{awd['peak_mb']:.0f} MB; distances_3d {d3['seconds']:.2f} s, "
          f"{d3['peak_mb']:.0f} MB; time ratio {awd['seconds'] / d3['seconds']:.3f}, memory "
          f"ratio {awd['peak_mb'] / max(d3['peak_mb'], 1e-9):.3f}")


def best(run, repeat: int = 3) -> float:
    """The shortest of ``repeat`` runs of ``run()``, seconds (one run first, untimed)."""
    run()
    seconds = []
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        seconds.append(time.perf_counter() - start)
    return min(seconds)


def ladder(voxel_3d: float) -> None:
    from pcmapq.align.rigid3d import align_3d
    from pcmapq.core.transform import affine
    from pcmapq.metrics.distances import distances_3d
    from pcmapq.metrics.map_gaussians import map_gaussians
    from testkit.kitti import pitch_ladder
    from testkit.mapeval import mapeval_as_coded

    start = time.perf_counter()
    truth, maps = pitch_ladder((0.05, 0.1, 0.2, 0.4))
    print(f"maps built in {time.perf_counter() - start:.1f} s; truth {len(truth):,} points")
    seconds = {run.__name__: best(lambda run=run: run(maps[0.1], truth))
               for run in (map_gaussians, distances_3d)}
    print(f"0.1 degree rung ({len(maps[0.1]):,} points) against the truth, best of three: "
          f"AWD+SCS {seconds['map_gaussians']:.2f} s, distances_3d "
          f"{seconds['distances_3d']:.2f} s, ratio "
          f"{seconds['map_gaussians'] / seconds['distances_3d']:.3f}")
    print("| pitch per scan (deg) | AWD as given (m) | SCS as given | voxels | AWD registered (m) "
          "| SCS registered | voxels | MapEval's code: AWD (m) | SCS |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for step, cloud in [(0.0, truth), *maps.items()]:
        given = map_gaussians(cloud, truth)
        reg = align_3d(cloud, truth, voxel=voxel_3d)
        registered = map_gaussians(affine(cloud, reg.transform), truth)
        coded = mapeval_as_coded(cloud, truth)
        print(f"| {step:g} | {given.awd_m:.4f} | {given.scs:.4f} | {given.voxels} "
              f"| {registered.awd_m:.4f} | {registered.scs:.4f} | {registered.voxels} "
              f"| {coded[0]:.4f} | {coded[1]:.4f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--ladder", action="store_true")
    parser.add_argument("--voxel-3d", type=float, default=0.5)
    args = parser.parse_args()
    cost(args.points)
    if args.ladder:
        ladder(args.voxel_3d)


if __name__ == "__main__":
    main()
