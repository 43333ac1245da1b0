"""Time and peak memory of `pcmapq eval CLOUD.ply TRUTH.png` on large clouds (issue 10, parts 2,
5 and 6), each beside its floor: Open3D's ``read_point_cloud`` + ``voxel_down_sample(0.05)`` of
the same file, measured in the same run.

    python -m bench.bench_clouds [--sizes 1,3,10,30] [--distances 3,10] [--tmp DIR]

Sizes are millions of points. Each cloud is a campus of distinct synthetic buildings
(``synth.building_plan(seed=k)`` on a lattice with 4 m gaps; walls 2.6 m high, floor and
ceiling, points every 0.018 m, 1 cm noise, 500 outliers per building), seeded-subsampled to the
exact size, in the robot's frame (the campus turned by 37 degrees and shifted, the floor 0.8 m
below the sensor), written as binary little-endian float32 x, y, z PLY (12 bytes a point) into a
temporary folder and deleted after. The truth is the campus's plan drawn at 0.05 m (PNG + YAML).

Every run is a fresh process (``python -m pcmapq eval ... --json``, or the floor's few lines),
its peak GB the child's peak memory (:func:`measured`). pcmapq s is the whole process's wall time
(interpreter, imports, every step); floor s is Open3D's read + voxel alone, timed inside its
process (its whole process, imports included, is "floor process s": importing Open3D alone
takes seconds). ratio = pcmapq s / floor s, the stricter of the two ratios. ``--before SRC``
also runs another pcmapq (``PYTHONPATH=SRC``, e.g. a checkout of main) on the same files.

``--distances`` compares pcmapq's 3D distances (``metrics.distances.distances_3d``: both clouds
voxel-downsampled to 0.05 m, then the nearest neighbour of every voxel both ways) with Open3D on
one pair of clouds of that size (the campus sampled twice, other seeds), in one fresh process
(``DISTANCE_CHILD``), best of two: the same work done with Open3D (``voxel_down_sample`` of
both, then ``compute_point_cloud_distance`` both ways: one direction a call), the two steps
apart, SciPy's ``cKDTree`` (``workers=-1``) on the same voxels, and what Open3D is usually
asked for, one direction on the raw points.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench.tree_memory import waited
from pcmapq.core.transform import Similarity2D
from pcmapq.io.writers import write_ros_map
from testkit import synth

#: Point spacing of the generated buildings, metres (about 3.4 M points per building).
SPACING = 0.018
#: At most this many points (millions) are kept of one building.
PER_BUILDING = 3.0
#: Building footprint and the gap between buildings, metres (synth.building_plan's default).
WIDTH, HEIGHT, GAP = 24.0, 16.0, 4.0
#: The campus seen from the robot's frame: p_truth = R(yaw) p_map + t (like data/sample).
POSE = Similarity2D(6.0, 8.0, float(np.radians(37.0)))
SENSOR_HEIGHT = 0.8
RESOLUTION = 0.05
#: The floor's voxel, metres.
FLOOR_VOXEL = 0.05

FLOOR_CHILD = r"""
import json, sys, time
import open3d as o3d
start = time.perf_counter()
cloud = o3d.io.read_point_cloud(sys.argv[1])
down = cloud.voxel_down_sample(float(sys.argv[2]))
print(json.dumps({"seconds": time.perf_counter() - start, "points": len(cloud.points),
                  "voxels": len(down.points)}))
"""

DISTANCE_CHILD = r"""
import json, sys, time
import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree
from pcmapq.metrics.distances import distances_3d
from pcmapq.core.voxels import voxel_centroids
sys.path.insert(0, sys.argv[1])
from bench.bench_clouds import campus_cloud

millions, voxel = float(sys.argv[2]), float(sys.argv[3])
a = campus_cloud(int(millions * 1e6), seed=0)
b = campus_cloud(int(millions * 1e6), seed=1000)

def best(fn, repeat=2):
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return min(out)

def o3d_cloud(xyz):
    return o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz))

def both_ways(da, db):
    return (np.asarray(da.compute_point_cloud_distance(db)),
            np.asarray(db.compute_point_cloud_distance(da)))

pa, pb = o3d_cloud(a), o3d_cloud(b)
ma, mb = voxel_centroids(a, voxel), voxel_centroids(b, voxel)
def scipy_queries(**tree):
    return (cKDTree(mb, **tree).query(ma, workers=-1)[0],
            cKDTree(ma, **tree).query(mb, workers=-1)[0])
def open3d_queries():
    return both_ways(o3d_cloud(ma), o3d_cloud(mb))
mine, theirs = scipy_queries(), open3d_queries()
same = max(float(np.abs(mine[0] - theirs[0]).max()), float(np.abs(mine[1] - theirs[1]).max()))
print(json.dumps({
    "points": [len(a), len(b)], "voxels": [len(ma), len(mb)], "max_diff_m": same,
    "pcmapq_whole": best(lambda: distances_3d(a, b, voxel)),
    "open3d_whole": best(lambda: both_ways(pa.voxel_down_sample(voxel),
                                           pb.voxel_down_sample(voxel))),
    "pcmapq_voxels": best(lambda: (voxel_centroids(a, voxel), voxel_centroids(b, voxel))),
    "open3d_voxels": best(lambda: (pa.voxel_down_sample(voxel), pb.voxel_down_sample(voxel))),
    "scipy_queries": best(scipy_queries),
    "scipy_unbalanced_queries": best(lambda: scipy_queries(balanced_tree=False)),
    "open3d_queries": best(open3d_queries),
    "open3d_one_way_raw": best(lambda: pa.compute_point_cloud_distance(pb), 1),
}))
"""


def layout(points: int) -> tuple[int, int]:
    """Columns and rows of the campus holding ``points`` points, no building over PER_BUILDING
    million."""
    buildings = max(1, math.ceil(points / (PER_BUILDING * 1e6)))
    columns = math.ceil(math.sqrt(buildings))
    return columns, math.ceil(buildings / columns)


def plans(columns: int, rows: int) -> list[np.ndarray]:
    """The campus's buildings, each a distinct plan (wall segments, metres, truth frame)."""
    out = []
    for k in range(columns * rows):
        shift = np.array([(k % columns) * (WIDTH + GAP), (k // columns) * (HEIGHT + GAP)])
        out.append(synth.building_plan(seed=k) + np.tile(shift, 2))
    return out


def building_clouds(points: int, seed: int = 0):
    """Yield the clouds (n_k, 3) float32, robot frame, metres, of the campus's buildings: ``points``
    points in all."""
    walls = plans(*layout(points))
    share = np.full(len(walls), points // len(walls))
    share[: points % len(walls)] += 1
    to_map = POSE.inverse()
    for k, (plan, keep) in enumerate(zip(walls, share, strict=True)):
        rng = np.random.default_rng(seed + k)
        cloud = synth.lidar_cloud(plan, spacing=SPACING, seed=seed + k)
        if keep > len(cloud):
            raise ValueError(f"a building has {len(cloud)} points, fewer than {keep}")
        cloud = cloud[np.sort(rng.choice(len(cloud), keep, replace=False))]
        cloud[:, :2] = to_map.apply(cloud[:, :2])
        cloud[:, 2] -= SENSOR_HEIGHT
        yield cloud.astype(np.float32)


def campus_cloud(points: int, seed: int = 0) -> np.ndarray:
    """The whole campus cloud (points, 3) float64, robot frame, metres."""
    return np.vstack(list(building_clouds(points, seed))).astype(np.float64)


def write_case(out: Path, points: int) -> tuple[Path, Path]:
    """Write ``out/cloud.ply`` (binary float32) and ``out/truth.png`` (+ YAML)."""
    walls = np.vstack(plans(*layout(points)))
    grid = synth.plan_grid(walls, RESOLUTION)
    truth = write_ros_map(out / "truth.png", synth.render(walls, grid), RESOLUTION,
                          grid.origin[:2])
    cloud = out / "cloud.ply"
    header = ("ply\nformat binary_little_endian 1.0\ncomment pcmapq bench_clouds\n"
              f"element vertex {points}\nproperty float x\nproperty float y\nproperty float z\n"
              "end_header\n")
    with cloud.open("wb") as f:
        f.write(header.encode("ascii"))
        for part in building_clouds(points):
            f.write(part.astype("<f4").tobytes())
    return cloud, truth


def measured(cmd: list[str], src: str | None = None) -> tuple[float, float, str]:
    """Run ``cmd`` in a fresh process (with ``PYTHONPATH=src`` if given): wall seconds, peak
    memory in GB (its child processes' counted: :func:`bench.tree_memory.waited`), its
    stdout."""
    env = dict(os.environ, PYTHONPATH=src) if src else None
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, env=env)
        status, _, gb = waited(proc)
        seconds = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        text = out.read().decode()
        if proc.returncode != 0:
            raise RuntimeError(f"{cmd[:4]} exited {proc.returncode}: {err.read().decode()[-2000:]}")
    return seconds, gb, text


def pcmapq_run(cloud: Path, truth: Path, src: str | None = None) -> dict:
    """``pcmapq eval cloud truth`` in a fresh process: seconds, GB, qualities, pose error."""
    result = cloud.with_name("result.json")
    seconds, gb, _ = measured([sys.executable, "-m", "pcmapq", "eval", str(cloud), str(truth),
                               "--json", str(result)], src)
    got = json.loads(result.read_text())
    error = POSE.inverse().compose(Similarity2D.from_dict(got["alignment"]))
    return {"s": seconds, "gb": gb,
            "quality": "/".join(f"{d['quality']:.2f}" for d in got["detectors"].values()),
            "pose_error": (math.hypot(error.tx, error.ty), error.yaw_deg)}


def cloud_row(millions: float, tmp: Path, before: str | None = None) -> dict:
    """Generate one case, run the floor and pcmapq (and the ``before`` pcmapq) on it, delete
    it."""
    points = int(round(millions * 1e6))
    case = tmp / f"cloud_{points}"
    case.mkdir()
    try:
        cloud, truth = write_case(case, points)
        process_s, floor_gb, text = measured([sys.executable, "-c", FLOOR_CHILD, str(cloud),
                                              str(FLOOR_VOXEL)])
        floor = json.loads(text.strip().splitlines()[-1])
        row = {"points": points, "bytes": cloud.stat().st_size, "floor_s": floor["seconds"],
               "floor_gb": floor_gb, "floor_process_s": process_s,
               "pcmapq": pcmapq_run(cloud, truth)}
        if before:
            row["before"] = pcmapq_run(cloud, truth, before)
    finally:
        shutil.rmtree(case)
    return row


def distance_row(millions: float) -> dict:
    """The 3D-distance comparison on a pair of clouds of ``millions`` M points each."""
    root = str(Path(__file__).resolve().parents[1])
    proc = subprocess.run([sys.executable, "-c", DISTANCE_CHILD, root, str(millions),
                           str(FLOOR_VOXEL)], capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def sizes(text: str) -> list[float]:
    return [float(s) for s in text.split(",") if s.strip()]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=sizes, default=sizes("1,3,10,30"),
                        help="millions of points, comma-separated (default 1,3,10,30; 100 "
                        "needs 1.2 GB of disk)")
    parser.add_argument("--distances", type=sizes, default=sizes("3,10"),
                        help="millions of points of the 3D-distance pairs ('' for none)")
    parser.add_argument("--before", metavar="SRC", help="also run the pcmapq found there "
                        "(PYTHONPATH=SRC) on the same files")
    parser.add_argument("--tmp", type=Path, default=None, help="folder for the generated files")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory(prefix="pcmapq_clouds_", dir=args.tmp) as tmp:
        for millions in args.sizes:
            rows.append(cloud_row(millions, Path(tmp), args.before))
            print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
    runs = ["pcmapq"] + (["before"] if args.before else [])
    print("| points | file MB | " + " | ".join(f"{r} s | {r} GB" for r in runs)
          + " | floor s | floor GB | ratio | floor process s | "
          + " | ".join(f"{r} quality harris/hough/sift | {r} pose error m / deg" for r in runs)
          + " |")
    print("|---:|---:|" + "---:|---:|" * len(runs) + "---:|---:|---:|---:|"
          + "---|---|" * len(runs))
    for r in rows:
        cells = [f"{r['points'] / 1e6:g} M", f"{r['bytes'] / 1e6:.0f}"]
        cells += [f"{r[k]['s']:.1f} | {r[k]['gb']:.2f}" for k in runs]
        cells += [f"{r['floor_s']:.1f}", f"{r['floor_gb']:.2f}",
                  f"{r['pcmapq']['s'] / r['floor_s']:.2f}", f"{r['floor_process_s']:.1f}"]
        cells += [f"{r[k]['quality']} | {r[k]['pose_error'][0]:.3f} / "
                  f"{abs(r[k]['pose_error'][1]):.3f}" for k in runs]
        print("| " + " | ".join(cells) + " |")
    if args.distances:
        print()
        print("| points per cloud | voxels per cloud | pcmapq `distances_3d` s | Open3D "
              "`voxel_down_sample` x 2 + `compute_point_cloud_distance` x 2 s | voxelising "
              "both: pcmapq / Open3D s | both directions on the same voxels: `cKDTree` / "
              "`cKDTree(balanced_tree=False)` / Open3D s | Open3D one direction on the raw "
              "points s | largest difference m |")
        print("|---:|---:|---:|---:|---:|---:|---:|---:|")
        for millions in args.distances:
            d = distance_row(millions)
            print(f"| {d['points'][0] / 1e6:g} M | {d['voxels'][0] / 1e6:.2f} M | "
                  f"{d['pcmapq_whole']:.2f} | {d['open3d_whole']:.2f} | "
                  f"{d['pcmapq_voxels']:.2f} / {d['open3d_voxels']:.2f} | "
                  f"{d['scipy_queries']:.2f} / {d['scipy_unbalanced_queries']:.2f} / "
                  f"{d['open3d_queries']:.2f} | {d['open3d_one_way_raw']:.2f} | "
                  f"{d['max_diff_m']:.1g} |")
            print(json.dumps(d), file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
