"""Throughput of ``pcmapq batch``: N small generated maps (default 50) against one truth, on
1 and 2 local worker processes and on a dask.distributed LocalCluster of 2 worker processes
(one thread each); prints a markdown table. Each run recomputes every row (``force``); its wall
time includes starting the local workers (a spawned process imports pcmapq, about 2-4 s) and
writing the table and figure, and on the cluster the workers importing pcmapq with their first
row (not the cluster's start). The cluster runs with Dask's default worker environment and with
it unset (see UNSET).

Run: ``python bench/bench_batch.py [N]``. Other processes on the machine slow it down: note
``uptime``'s load beside the numbers.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from pcmapq.batch import read_rows, run_batch
from pcmapq.core.transform import Similarity2D
from pcmapq.io.writers import write_ros_map
from pcmapq.testing import synth

#: Dask's worker environment (``distributed.nanny.pre-spawn-environ``) unset, as
#: docs/commands/batch.md advises: its MALLOC_TRIM_THRESHOLD_ and one-thread BLAS/OpenMP slow
#: pcmapq down.
UNSET = {f"distributed.nanny.pre-spawn-environ.{k}": None for k in (
    "MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")}
#: The truth's plan (metres) and the resolution of every image, metres per pixel.
WIDTH, HEIGHT, RESOLUTION = 24.0, 16.0, 0.05


def write_image(segments: np.ndarray, path: Path) -> None:
    """Wall segments (metres) as a ROS map image with its YAML."""
    grid = synth.plan_grid(segments, RESOLUTION)
    write_ros_map(path, synth.render(segments, grid), RESOLUTION, grid.origin[:2])


def make_inputs(folder: Path, n: int) -> Path:
    """The truth and ``n`` maps of it (each from another pose, one wall moved, 0-2 boxes of
    clutter); the manifest's path."""
    rng = np.random.default_rng(0)
    plan = synth.building_plan(0, WIDTH, HEIGHT)
    write_image(plan, folder / "truth.png")
    lines = ["name,map,truth"]
    for i in range(n):
        x, y, yaw = rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-20, 20)
        seen = synth.move_wall(plan, int(rng.integers(len(plan))), (0.2, 0.0))
        seen = synth.clutter(seen, int(rng.integers(3)), seed=i)
        tf = Similarity2D(x, y, np.radians(yaw))
        write_image(synth.transform_segments(seen, tf.inverse()), folder / f"map{i:03d}.png")
        lines.append(f"map{i:03d},map{i:03d}.png,truth.png")
    (folder / "runs.csv").write_text("\n".join(lines) + "\n")
    return folder / "runs.csv"


def timed(label: str, rows: list, out: Path, **how) -> tuple[str, float, int]:
    start = time.perf_counter()
    outcomes = run_batch(rows, out, force=True, **how)
    failed = sum(o.exit_code != 0 for o in outcomes)
    return label, time.perf_counter() - start, failed


def main(n: int) -> None:
    import dask
    from dask.distributed import LocalCluster

    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        rows = read_rows(make_inputs(folder, n), {})
        runs = [timed("1 local worker", rows, folder / "w1", workers=1),
                timed("2 local workers", rows, folder / "w2", workers=2)]
        for label, config in (("Dask's default worker environment", {}),
                              ("worker environment unset (docs/commands/batch.md)", UNSET)):
            with dask.config.set(config), LocalCluster(
                    n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                    dashboard_address=None) as cluster:
                runs.append(timed(f"LocalCluster, 2 workers, {label}", rows,
                                  folder / "dask", scheduler=cluster.scheduler_address))
    base = runs[0][1]
    print(f"{n} maps ({WIDTH:g} m x {HEIGHT:g} m, {RESOLUTION} m/px), {os.cpu_count()} cores, "
          f"load (1 min) before: {load:.2f}, after: {os.getloadavg()[0]:.2f}\n")
    print("| run | wall s | maps/s | speed-up vs 1 worker | failed rows |")
    print("|---|---:|---:|---:|---:|")
    for label, seconds, failed in runs:
        print(f"| {label} | {seconds:.1f} | {n / seconds:.2f} | {base / seconds:.2f} | "
              f"{failed} |")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 50)
