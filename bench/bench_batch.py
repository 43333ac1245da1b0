"""Throughput of ``pcmapq batch`` on local processes and on Dask clusters, as ratios to 2 local
processes measured in the same run.

    python -m bench.bench_batch [N] [--repeat R]

N small generated maps (default 50) against one truth, every row recomputed (``--force``), each
batch a fresh ``pcmapq batch`` process, one at a time, ``R`` rounds (default 2) of the same runs
in the same order:

- 1 and 2 local worker processes (``--workers``): the wall time includes starting them (a
  spawned process imports pcmapq);
- a ``dask.distributed`` LocalCluster of 2 worker processes, one thread each, and a cluster
  started by hand as on several machines (``dask scheduler`` and two ``dask worker
  tcp://127.0.0.1:PORT --nthreads 1`` processes on loopback), both with Dask's default worker
  configuration. Each round starts them afresh and stops them after the batch, untimed, so the
  batch's time includes its workers importing pcmapq with their first row, as a local batch's
  includes its processes' start;
- 2 local processes with the allocator thresholds a Dask worker starts with (:data:`DASKS`),
  which ``pcmapq batch`` replaces for its rows (:mod:`pcmapq.batch.allocator`) but leaves
  alone here: what they cost.

Per run: the wall time, and the CPU time and minor page faults of every process of the run
(the batch, its local workers, the cluster's scheduler, nannies and workers while it runs): the
steadier figures on a busy machine. Each round's figures are ratios to that round's 2 local
processes. ``others' CPU s`` is the CPU time other processes used during a run (the machine's
busy time less this benchmark's processes'): a run beside others' work is slower, and its
ratios say less. The table gives, per run, the medians over the rounds in which it and the
round's 2 local processes ran alone (others' CPU at most :data:`ALONE` of the run's own), or
over all rounds when there are none.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.transform import Similarity2D
from pcmapq.io.writers import write_ros_map
from testkit import synth

#: The truth's plan (metres) and the resolution of every image, metres per pixel.
WIDTH, HEIGHT, RESOLUTION = 24.0, 16.0, 0.05
PCMAPQ = [sys.executable, "-m", "pcmapq"]
DASK = [sys.executable, "-m", "dask"]
#: The reference run, every ratio's denominator.
REFERENCE = "2 local processes"
#: The allocator thresholds of a process a Dask nanny starts (MALLOC_TRIM_THRESHOLD_=65536 fixes
#: the trim threshold and so the mmap threshold at glibc's initial 128 KiB), with the mmap
#: threshold given too, so that pcmapq.batch.allocator leaves them alone: what a Dask worker's
#: rows would cost without it.
DASKS = {"MALLOC_TRIM_THRESHOLD_": "65536", "MALLOC_MMAP_THRESHOLD_": str(128 * 1024)}
#: A run ran alone when other processes used at most this share of its own CPU time meanwhile.
ALONE = 0.05


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


def _busy_seconds() -> float:
    """CPU seconds the machine has been busy, all cores (/proc/stat)."""
    with open("/proc/stat") as f:
        ticks = [int(v) for v in f.readline().split()[1:8]]
    return (sum(ticks) - ticks[3] - ticks[4]) / os.sysconf("SC_CLK_TCK")


def _own() -> tuple[float, int]:
    """CPU seconds and minor page faults of this process and of every process it started,
    alive or ended: its own rusage and its ended children's, and each live descendant's
    figures with its ended children's (/proc/PID/stat)."""
    usage = [resource.getrusage(who) for who in (resource.RUSAGE_SELF,
                                                 resource.RUSAGE_CHILDREN)]
    cpu = sum(u.ru_utime + u.ru_stime for u in usage)
    faults = sum(u.ru_minflt for u in usage)
    parents: dict[int, int] = {}
    figures: dict[int, tuple[int, int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:  # ended meanwhile
                continue
            parents[int(entry)] = int(fields[1])
            figures[int(entry)] = (sum(int(v) for v in fields[11:15]),
                                   int(fields[7]) + int(fields[8]))
    mine, todo = set(), [os.getpid()]
    while todo:
        pid = todo.pop()
        children = [p for p, parent in parents.items() if parent == pid and p not in mine]
        mine.update(children)
        todo += children
    return (cpu + sum(figures[p][0] for p in mine) / os.sysconf("SC_CLK_TCK"),
            faults + sum(figures[p][1] for p in mine))


def _counters() -> tuple[float, float, int] | None:
    """The machine's busy CPU seconds, and this benchmark's own CPU seconds and minor page
    faults (:func:`_own`); None without /proc."""
    try:
        return (_busy_seconds(), *_own())
    except OSError:
        return None


@dataclass(frozen=True)
class Run:
    """One batch: wall seconds; CPU seconds and minor page faults of its processes, CPU
    seconds of other processes meanwhile (each None without /proc); rows that failed."""

    seconds: float
    cpu: float | None
    faults: int | None
    others: float | None
    failed: int


def timed(args: list[str], env: dict[str, str] | None = None) -> Run:
    """Run one ``pcmapq batch ... --json -`` command (exit 0 or 1, else stop here), with
    ``env`` added to its environment."""
    before = _counters()
    start = time.perf_counter()
    child = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             env={**os.environ, **(env or {})})
    out, err = child.communicate()
    seconds = time.perf_counter() - start
    after = _counters()
    if child.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(args)}: exit {child.returncode}: {err.decode()}")
    failed = sum(r["exit_code"] != 0 for r in json.loads(out)["rows"])
    if before is None or after is None:
        return Run(seconds, None, None, None, failed)
    busy, cpu, faults = (a - b for a, b in zip(after, before, strict=True))
    return Run(seconds, cpu, int(faults), max(0.0, busy - cpu), failed)


@contextlib.contextmanager
def local_cluster(workers: int) -> Iterator[str]:
    """A LocalCluster of ``workers`` processes, one thread each, on loopback; its address."""
    from dask.distributed import LocalCluster

    environ = dict(os.environ)
    try:
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          host="127.0.0.1", dashboard_address=None) as cluster:
            yield cluster.scheduler_address
    finally:  # its nannies set their workers' environment in ours, for good: undone
        os.environ.clear()
        os.environ.update(environ)


@contextlib.contextmanager
def hand_started_cluster(workers: int, folder: Path) -> Iterator[str]:
    """``dask scheduler`` and ``workers`` ``dask worker ADDRESS --nthreads 1`` processes on
    loopback, as a user starts them on several machines, each in a session of its own; its
    address. All stopped at the end."""
    from dask.distributed import Client

    scheduler_file = folder / "scheduler.json"
    scheduler_file.unlink(missing_ok=True)
    started = [subprocess.Popen([*DASK, "scheduler", "--host", "127.0.0.1", "--port", "0",
                                 "--no-dashboard", "--scheduler-file", str(scheduler_file)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True)]
    try:
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() or not scheduler_file.read_text().strip():
            if time.monotonic() > deadline or started[0].poll() is not None:
                raise SystemExit("dask scheduler did not start")
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        started += [subprocess.Popen([*DASK, "worker", address, "--nthreads", "1",
                                      "--host", "127.0.0.1", "--no-dashboard"],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     start_new_session=True) for _ in range(workers)]
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(workers, timeout=60)
        yield address
    finally:
        for process in reversed(started):  # the workers first, then the scheduler
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGTERM)
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", nargs="?", type=int, default=50, help="maps (default 50)")
    parser.add_argument("--repeat", type=int, default=2, help="rounds (default 2)")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        manifest = make_inputs(folder, args.n)
        batch = [*PCMAPQ, "batch", str(manifest), "--force", "--json", "-"]
        local = [*batch, "--workers", "2"]
        runs = {"1 local process": ([*batch, "--workers", "1"], None, {}),
                REFERENCE: (local, None, {}),
                "LocalCluster, 2 workers x 1 thread": (batch, local_cluster, {}),
                "hand-started cluster: dask scheduler, 2 x dask worker --nthreads 1":
                    (batch, lambda n: hand_started_cluster(n, folder), {}),
                f"{REFERENCE} with a Dask worker's allocator, unguarded": (local, None, DASKS)}
        got: dict[str, list[Run]] = {label: [] for label in runs}
        for round_ in range(args.repeat):
            for i, (label, (command, cluster, env)) in enumerate(runs.items()):
                out = ["--out", str(folder / f"out-{round_}-{i}")]
                if cluster is None:
                    got[label].append(timed([*command, *out], env))
                else:
                    with cluster(2) as address:
                        got[label].append(timed([*command, *out, "--scheduler", address]))
                print(f"round {round_ + 1}: {label}: {got[label][-1]}", file=sys.stderr)
    print(f"{args.n} maps ({WIDTH:g} m x {HEIGHT:g} m, {RESOLUTION} m/px), {os.cpu_count()} "
          f"cores, {args.repeat} rounds; load (1 min) before: {load:.2f}, after: "
          f"{os.getloadavg()[0]:.2f}\n")
    print(f"| run | rounds alone | wall s | wall / {REFERENCE} | CPU s | CPU / {REFERENCE} | "
          "page faults | maps/s | others' CPU s (most) | failed rows |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for label, results in got.items():
        pairs = list(zip(results, got[REFERENCE], strict=True))
        alone = [(r, ref) for r, ref in pairs if _alone(r) and _alone(ref)]
        used = alone or pairs
        seconds = statistics.median(r.seconds for r, _ in used)
        cpu = [(r.cpu, ref.cpu) for r, ref in used if r.cpu is not None and ref.cpu]
        faults = [r.faults / 1e6 for r, _ in used if r.faults is not None]
        print(f"| {label} | {len(alone)} of {len(pairs)} | {seconds:.1f} | "
              f"{statistics.median(r.seconds / ref.seconds for r, ref in used):.2f} | "
              f"{_median([c for c, _ in cpu], '.1f')} | "
              f"{_median([c / ref for c, ref in cpu], '.2f')} | "
              f"{_median(faults, '.2f')} M | {args.n / seconds:.2f} | "
              f"{max((r.others or 0 for r, _ in used), default=0):.1f} | "
              f"{max(r.failed for r, _ in used)} |")


def _alone(run: Run) -> bool:
    """Whether a run ran alone: other processes used at most :data:`ALONE` of its CPU time
    meanwhile (unknown without /proc: taken as alone)."""
    return run.others is None or run.cpu is None or run.others <= ALONE * run.cpu


def _median(values: list[float], form: str) -> str:
    return format(statistics.median(values), form) if values else "-"


if __name__ == "__main__":
    main()
