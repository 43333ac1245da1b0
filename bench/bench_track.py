"""`pcmapq track` against one `pcmapq eval` of the run's final map: is scoring a run as it grows
within a few evaluations' time?

    python bench/bench_track.py [--repeat N]   prints a markdown table (docs/benchmarks.md)

Cases (from ../shared/data; a case whose data is absent is left out):

- CARMEN logs scored against their own corrected map (`pcmapq eval LOG LOG`; `pcmapq track LOG
  LOG --every 20`): Intel (910 scans, the issue's 1000-scan case) and FHW (489 scans);
- KITTI 00's 20 velodyne scans (about 124k points each) at KISS-ICP's poses against the map of
  KITTI's reference poses (`pcmapq eval kiss.ply reference.ply`; `pcmapq track velodyne/ --poses
  kiss.txt reference.ply --every 2`); the maps and poses are made first, untimed.

Each command runs in a fresh process, one at a time: its wall time (the best of ``--repeat``
runs) and its peak memory (max RSS, from the process's own rusage).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
PCMAPQ = [sys.executable, "-m", "pcmapq"]
#: KITTI sequence 00's velodyne -> camera transform Tr, row-major 3x4 (../shared/README.md).
TR = ("4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
      "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
      "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01")


def timed(args: list[str]) -> tuple[float, float]:
    """Run one command; its wall time (s) and peak memory (MB). Fails loudly on exit != 0."""
    start = time.perf_counter()
    child = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    seconds = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(args)}: exit {status}: {child.stderr.read().decode()}")
    return seconds, usage.ru_maxrss / 1024


def best(args: list[str], repeat: int) -> tuple[float, float]:
    runs = [timed(args) for _ in range(repeat)]
    return min(r[0] for r in runs), max(r[1] for r in runs)


def cases(work: Path) -> list[tuple[str, str, list[str], list[str]]]:
    """(name, steps, eval command, track command) of every case whose data is here."""
    found = []
    for name, log, scans in (("Intel, CARMEN log", "intel-corrected.log.gz", 910),
                             ("FHW, CARMEN log", "fhw-corrected.log.gz", 489)):
        path = DATA / "carmen" / log
        if path.exists():
            steps = f"{scans} scans, every 20: {-(-scans // 20)} steps"
            found.append((name, steps, [*PCMAPQ, "eval", str(path), str(path), "--json",
                                        str(work / "eval.json")],
                          [*PCMAPQ, "track", str(path), str(path), "--every", "20", "--out",
                           str(work / "run"), "-q"]))
    velodyne = DATA / "kitti00" / "velodyne"
    if velodyne.exists():
        calib = work / "Tr.txt"
        calib.write_text(TR + "\n")
        reference, kiss, poses = work / "reference.ply", work / "kiss.ply", work / "kiss.txt"
        subprocess.run([*PCMAPQ, "map", str(velodyne), "--poses",
                        str(DATA / "kitti00" / "poses.txt"), "--calib", str(calib), "--out",
                        str(reference)], check=True, capture_output=True)
        subprocess.run([*PCMAPQ, "map", str(velodyne), "--out", str(kiss), "--poses-out",
                        str(poses)], check=True, capture_output=True)
        found.append(("KITTI 00, 20 velodyne scans", "20 scans, every 2: 10 steps",
                      [*PCMAPQ, "eval", str(kiss), str(reference), "--json",
                       str(work / "eval.json")],
                      [*PCMAPQ, "track", str(velodyne), "--poses", str(poses), str(reference),
                       "--every", "2", "--out", str(work / "run"), "-q"]))
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each command (best)")
    repeat = parser.parse_args().repeat
    print("| case | steps | `pcmapq eval` of the final map | `pcmapq track` | ratio |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, steps, evaluate, track in cases(Path(tmp)):
            (e_s, e_mb), (t_s, t_mb) = best(evaluate, repeat), best(track, repeat)
            print(f"| {name} | {steps} | {e_s:.1f} s, {e_mb:.0f} MB | {t_s:.1f} s, "
                  f"{t_mb:.0f} MB | {t_s / e_s:.1f}x |", flush=True)


if __name__ == "__main__":
    main()
