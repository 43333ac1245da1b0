"""Time, memory and results of pcmapq.align.rigid3d.align_3d on real 3D data; a markdown table.

    python bench/bench_rigid3d.py [--save runs.json] [--against before.json]

Cases: the LiDAR registration pair (../shared/data/registration, known transform), the same
pair with the source turned by 150 degrees, and the first 20 KITTI 00 scans mapped by KISS-ICP
registered to the map from KITTI's reference poses (both at 0.1 m, built once into a cache
folder outside the repository), at voxels 0.3 and 0.5 m, and at 0.3 m from the identity
(``init``: refinement only). Each case runs in a fresh process, twice: "same" says whether the
two transforms are byte-identical; seconds (wall clock) and CPU seconds (all threads) are the
faster run's. "peak MB" is the process's peak RSS (VmHWM; ru_maxrss would carry the parent's
over exec), "+MB" its rise over the RSS before the first call (libraries and inputs loaded).
"vs truth" is the error against the known transform; with ``--against`` a run saved by an
earlier ``--save`` (e.g. with PYTHONPATH on an older checkout's src), "vs before" is the
difference to its transform, translation (m) / rotation (deg), or "identical" bit for bit.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
#: Velodyne -> left camera of KITTI 00 (its calib.txt, ``Tr:``), row-major 3x4.
TR_00 = ("4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
         "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
         "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01")
#: name: (source file, target file, truth file or "", turn of the source (deg about z), voxel,
#: start from the identity)
CASES = {
    "pair, 0.3 m": ("pair_source.npy", "pair_target.npy", "pair_truth.npy", 0.0, 0.3, False),
    "pair turned 150 deg, 0.3 m": ("pair_source.npy", "pair_target.npy", "pair_truth.npy",
                                   150.0, 0.3, False),
    "KITTI 20 scans, 0.3 m": ("kitti_kiss.npy", "kitti_truth.npy", "", 0.0, 0.3, False),
    "KITTI 20 scans, 0.5 m": ("kitti_kiss.npy", "kitti_truth.npy", "", 0.0, 0.5, False),
    "KITTI 20 scans, 0.3 m, init": ("kitti_kiss.npy", "kitti_truth.npy", "", 0.0, 0.3, True),
}

CHILD = r"""
import json, sys, time
from pathlib import Path
import numpy as np
from scipy.spatial.transform import Rotation
from pcmapq.align.rigid3d import align_3d

cache, spec = Path(sys.argv[1]), json.loads(sys.argv[2])
source, target = np.load(cache / spec[0]), np.load(cache / spec[1])
turn = np.eye(4)
turn[:3, :3] = Rotation.from_euler("z", spec[3], degrees=True).as_matrix()
source = source @ turn[:3, :3].T
init = np.eye(4) if spec[5] else None
def status_mb(key):
    line = next(x for x in open("/proc/self/status") if x.startswith(key + ":"))
    return int(line.split()[1]) / 1024
rss_before = status_mb("VmRSS")
runs = []
for _ in range(2):
    t0, c0 = time.perf_counter(), time.process_time()
    result = align_3d(source, target, voxel=spec[4], init=init)
    runs.append((time.perf_counter() - t0, time.process_time() - c0, result))
(seconds, cpu, first), (seconds2, cpu2, second) = runs
print(json.dumps({
    "transform": (first.transform @ turn).tolist(), "fitness": first.fitness,
    "rmse": first.rmse_m, "seconds": min(seconds, seconds2), "cpu": min(cpu, cpu2),
    "same": bool(np.array_equal(first.transform, second.transform)
                 and (first.fitness, first.rmse_m) == (second.fitness, second.rmse_m)),
    "peak_mb": status_mb("VmHWM"),
    "rss_before_mb": rss_before, "points": [len(source), len(target)]}))
"""


def prepare(cache: Path) -> None:
    """Write the inputs (N, 3) float64 .npy into ``cache`` unless there already."""
    cache.mkdir(parents=True, exist_ok=True)
    if not (cache / "pair_truth.npy").exists():
        import open3d as o3d

        for name in ("source", "target"):
            cloud = o3d.io.read_point_cloud(str(DATA / "registration" / f"{name}.ply"))
            np.save(cache / f"pair_{name}.npy", np.asarray(cloud.points, dtype=np.float64))
        truth = np.loadtxt(DATA / "registration" / "T_target_source.txt").reshape(4, 4)
        np.save(cache / "pair_truth.npy", truth)
    if not (cache / "kitti_truth.npy").exists():
        from pcmapq.mapping import (
            build_map_from_poses,
            build_map_kiss,
            lidar_poses_from_camera,
            read_kitti_poses,
        )

        kitti = DATA / "kitti00"
        kiss_map, _ = build_map_kiss(kitti, max_scans=20, voxel=0.1)
        tr = np.eye(4)
        tr[:3, :4] = np.array(TR_00.split(), dtype=np.float64).reshape(3, 4)
        poses = lidar_poses_from_camera(read_kitti_poses(kitti / "poses.txt")[:20], tr)
        np.save(cache / "kitti_kiss.npy", kiss_map)
        np.save(cache / "kitti_truth.npy", build_map_from_poses(kitti, poses, None, voxel=0.1))


def difference(a: np.ndarray, b: np.ndarray) -> str:
    """'translation m / rotation deg' of ``inv(b) @ a``."""
    delta = np.linalg.inv(b) @ a
    cos = np.clip((np.trace(delta[:3, :3]) - 1) / 2, -1.0, 1.0)
    return f"{np.linalg.norm(delta[:3, 3]):.4f} / {np.degrees(np.arccos(cos)):.4f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cache", type=Path, default=Path("/tmp/pcmapq-bench-rigid3d"))
    parser.add_argument("--save", type=Path, help="write the runs (transforms too) as JSON")
    parser.add_argument("--against", type=Path, help="a saved run to compare transforms with")
    args = parser.parse_args()
    prepare(args.cache)
    runs = {}
    for name, spec in CASES.items():
        proc = subprocess.run([sys.executable, "-c", CHILD, str(args.cache), json.dumps(spec)],
                              capture_output=True, text=True, check=True)
        runs[name] = json.loads(proc.stdout.strip().splitlines()[-1])
    before = json.loads(args.against.read_text()) if args.against else {}
    if args.save:
        args.save.write_text(json.dumps(runs, indent=1))
    print("| case | points (source / target) | seconds | CPU s | peak MB | +MB | same | fitness | "
          "RMSE m | vs truth m / deg | vs before m / deg |")
    print("|---|---|---:|---:|---:|---:|---|---:|---:|---|---|")
    for name, r in runs.items():
        truth_file = CASES[name][2]
        transform = np.array(r["transform"])
        truth = difference(transform, np.load(args.cache / truth_file)) if truth_file else "-"
        old = "-"
        if name in before:
            earlier = np.array(before[name]["transform"])
            old = "identical" if np.array_equal(transform, earlier) else difference(
                transform, earlier)
        print(f"| {name} | {r['points'][0]} / {r['points'][1]} | {r['seconds']:.2f} | "
              f"{r['cpu']:.2f} | {r['peak_mb']:.0f} | {r['peak_mb'] - r['rss_before_mb']:.0f} | "
              f"{'yes' if r['same'] else 'NO'} | {r['fitness']:.4f} | {r['rmse']:.4f} | "
              f"{truth} | {old} |")


if __name__ == "__main__":
    main()
