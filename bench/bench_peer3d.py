"""pcmapq against CloudAnalyzer on two 3D clouds (issue 57's speed bound): ``pcmapq eval MAP
TRUTH --json OUT`` by default against CloudAnalyzer's ``ca compare`` plus ``ca map-evaluate``
on the same pair, in one run.

    python -m bench.bench_peer3d [--repeat 3] [--cache DIR]
    python -m bench --only peer3d [--doc] [--save]

The pair: KITTI 00's first 20 scans at their reference poses (the truth,
:func:`bench.validation.kitti.reference_map`) and the same scans with a pitch drift of
:data:`PITCH_DEG` degrees a scan (the map, :func:`testkit.kitti.pitched`), both 0.1 m voxel
centroids as ``pcmapq map`` builds them, written once as .ply into the cache folder.

Each side runs in fresh processes, as a user runs them, with the defaults of each tool:
pcmapq's evaluation (3D registration, 3D distances, AWD and SCS, the 3D consistency map, the 3D
structures, the 2D detectors on the wall band, the no-reference figures); CloudAnalyzer's
``ca compare MAP TRUTH --json OUT`` (GICP on the whole clouds, then nearest-neighbour
distances) and ``ca map-evaluate MAP TRUTH --output-json OUT`` (nearest-neighbour accuracy and
completeness, AWD and SCS at its default 3 m voxel); and pcmapq's evaluation with
``--init-3d identity``: its 3D registration's ICP started in the frame given, as ``ca
compare``'s GICP starts, with no global search. The four commands run in turn, ``repeat``
times (at least :data:`RUNS`), so that the machine's load slows them alike; of each, the median
wall seconds, peak memory (:func:`bench.bench_clouds.measured`'s: child processes counted)
and CPU seconds (user + system, all its threads and child processes). The time
ratio is pcmapq's default median over the sum of the two ``ca`` medians, the bound issue 57
sets being 1.0 (the run from the frame given has its own ratio, with no bound); the memory
ratio is pcmapq's peak over the larger of the two ``ca`` peaks (they run one after the
other). CloudAnalyzer goes in a virtual environment of its own, its ``ca`` command on
the PATH (``python -m venv /opt/cloudanalyzer && /opt/cloudanalyzer/bin/pip install
cloudanalyzer && ln -s /opt/cloudanalyzer/bin/ca /usr/local/bin/ca``): it requires Open3D below
0.20, and installed beside pcmapq it would overwrite Open3D's files. Without it, or without the
KITTI data, the case is skipped with one line saying so.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from bench.tree_memory import waited
from testkit.paths import SHARED_DATA

#: Pitch drift of the map, degrees a scan (scan k turned by k times it).
PITCH_DEG = 0.2
#: KITTI 00's scans in the pair.
SCANS = 20
#: Runs of each command, at least (the median is kept).
RUNS = 3
#: The pair's name in the ratios.
NAME = f"peer3d/KITTI {SCANS} scans, pitch {PITCH_DEG:g} deg"
#: pcmapq's evaluation with its 3D registration started in the frame given.
GIVEN = "pcmapq eval --init-3d identity"


@dataclass(frozen=True)
class Run:
    """One command's run in a fresh process: wall seconds, peak RSS in GB, CPU seconds of all
    its threads (user + system)."""

    seconds: float
    gb: float
    cpu: float


def run(cmd: list[str]) -> Run:
    """``cmd`` in a fresh process, its output discarded; RuntimeError naming it if it fails."""
    with tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
        status, usage, gb = waited(proc)
        seconds = time.perf_counter() - start
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            raise RuntimeError(f"{' '.join(cmd[:4])} failed: {err.read().decode()[-2000:]}")
    return Run(seconds, gb, usage.ru_utime + usage.ru_stime)


def kitti_pitched_pair(cache: Path) -> tuple[Path, Path] | None:
    """(map, truth) .ply of :data:`SCANS` KITTI 00 scans, the map pitched by
    :data:`PITCH_DEG` a scan, written once into ``cache``; None without the data."""
    data = SHARED_DATA / "kitti00"
    if not (data / "velodyne").is_dir():
        return None

    def write(folder: Path) -> None:
        from bench.validation.kitti import reference_map
        from pcmapq.io.writers import write_cloud
        from pcmapq.mapping import build_map_from_poses
        from testkit.kitti import pitched

        truth, poses = reference_map(data, SCANS)
        write_cloud(folder / "truth.ply", truth)
        write_cloud(folder / "map.ply", build_map_from_poses(
            data / "velodyne", pitched(poses, PITCH_DEG), max_scans=SCANS).points)

    from bench.timing import written

    folder = written(cache / f"kitti{SCANS}_pitch{PITCH_DEG:g}", write)
    return folder / "map.ply", folder / "truth.ply"


def commands(map_path: Path, truth: Path, ca: str, out: Path) -> dict[str, list[str]]:
    """The four commands by name, each writing its JSON into ``out``: pcmapq's evaluation by
    default and with its 3D registration started in the frame given (``--init-3d identity``,
    as ``ca compare`` starts its GICP), and CloudAnalyzer's two."""
    pcmapq = [sys.executable, "-m", "pcmapq", "eval", str(map_path), str(truth)]
    return {"pcmapq eval": [*pcmapq, "--json", str(out / "pcmapq.json")],
            GIVEN: [*pcmapq, "--init-3d", "identity", "--json", str(out / "pcmapq_given.json")],
            "ca compare": [ca, "compare", str(map_path), str(truth), "--json",
                           str(out / "compare.json")],
            "ca map-evaluate": [ca, "map-evaluate", str(map_path), str(truth), "--output-json",
                                str(out / "map_evaluate.json")]}


def measure(cache: Path, repeat: int = RUNS, log=print) -> dict[str, list[Run]] | None:
    """Each command's runs on the pair, interleaved; None (``log`` says why) without
    CloudAnalyzer or the data."""
    ca = shutil.which("ca")
    if ca is None:
        log("peer3d: skipped, CloudAnalyzer's `ca` is not on the PATH (pip install "
            "cloudanalyzer, in a virtual environment of its own: bench/bench_peer3d.py)")
        return None
    pair = kitti_pitched_pair(cache)
    if pair is None:
        log(f"peer3d: skipped, {SHARED_DATA / 'kitti00'} is absent")
        return None
    cmds = commands(*pair, ca, cache)
    runs: dict[str, list[Run]] = {name: [] for name in cmds}
    for k in range(max(repeat, RUNS)):
        for name, cmd in cmds.items():
            runs[name].append(run(cmd))
            last = runs[name][-1]
            log(f"peer3d run {k + 1}: {name} {last.seconds:.1f} s, {last.gb:.2f} GB, CPU "
                f"{last.cpu:.1f} s; load {os.getloadavg()[0]:.1f}")
    return runs


def median(runs: list[Run], field: str) -> float:
    return statistics.median(getattr(r, field) for r in runs)


def ratios(runs: dict[str, list[Run]]) -> tuple[float, float, float]:
    """(time, memory, CPU) ratios of pcmapq's medians to CloudAnalyzer's (module docstring)."""
    ours, compare, evaluate = runs["pcmapq eval"], runs["ca compare"], runs["ca map-evaluate"]
    return (median(ours, "seconds") / (median(compare, "seconds") + median(evaluate, "seconds")),
            median(ours, "gb") / max(median(compare, "gb"), median(evaluate, "gb")),
            median(ours, "cpu") / (median(compare, "cpu") + median(evaluate, "cpu")))


def table(runs: dict[str, list[Run]]) -> str:
    """Markdown: each command's runs and medians, then the ratios."""
    lines = ["| command | wall s (runs) | median s | peak GB | CPU s |", "|---|---|---:|---:|---:|"]
    for name, found in runs.items():
        lines.append(f"| `{name}` | {' / '.join(f'{r.seconds:.1f}' for r in found)} | "
                     f"{median(found, 'seconds'):.1f} | {median(found, 'gb'):.2f} | "
                     f"{median(found, 'cpu'):.1f} |")
    time_ratio, memory_ratio, cpu_ratio = ratios(runs)
    lines.append(f"\ntime ratio {time_ratio:.2f} (bound 1.0), memory ratio {memory_ratio:.2f}, "
                 f"CPU ratio {cpu_ratio:.2f}")
    return "\n".join(lines)


def case(cache: Path, repeat: int) -> list:
    """The ratios of :mod:`bench.ratios`: time (target 1.0) and memory."""
    from bench.timing import Ratio

    runs = measure(cache, repeat, log=lambda line: print(line, file=sys.stderr, flush=True))
    if runs is None:
        return []
    ours, compare, evaluate = runs["pcmapq eval"], runs["ca compare"], runs["ca map-evaluate"]
    time_ratio, memory_ratio, _ = ratios(runs)
    peer = (f"ca compare {median(compare, 'seconds'):.1f} s + ca map-evaluate "
            f"{median(evaluate, 'seconds'):.1f} s")
    given = median(runs[GIVEN], "seconds")
    return [Ratio(f"{NAME}/time", time_ratio, f"pcmapq eval {median(ours, 'seconds'):.1f} s",
                  peer, 1.0),
            Ratio(f"{NAME}/time, from the frame given", given / (
                median(compare, "seconds") + median(evaluate, "seconds")),
                  f"{GIVEN} {given:.1f} s", peer),
            Ratio(f"{NAME}/memory", memory_ratio, f"pcmapq eval {median(ours, 'gb'):.2f} GB",
                  f"ca compare {median(compare, 'gb'):.2f} GB, ca map-evaluate "
                  f"{median(evaluate, 'gb'):.2f} GB")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=RUNS, help="runs of each command")
    parser.add_argument("--cache", type=Path, default=Path("/tmp/pcmapq-bench"))
    args = parser.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    print(f"load before: {os.getloadavg()}", file=sys.stderr)
    runs = measure(args.cache, args.repeat, log=lambda line: print(line, file=sys.stderr))
    print(f"load after: {os.getloadavg()}", file=sys.stderr)
    if runs is not None:
        print(table(runs))


if __name__ == "__main__":
    main()
