"""Whole commands in fresh processes, start-up included: `pcmapq inspect` on map-metrics' depth
data against map-metrics' own whole run, and what pcmapq's commands cost before any work; a
markdown table.

    python bench/bench_startup.py [--repeat 3] [--skip-theirs] [--baseline SRC]

The runs, each a fresh process started as a user starts it (``python -m pcmapq ...`` on this
checkout's ``src``):

- ``python -c pass``: the interpreter's own start, the floor of any command;
- ``pcmapq --version``, ``pcmapq --help``, ``pcmapq inspect --help``, ``pcmapq eval --help``:
  start-up alone (the listing; one command's help, which loads its options and their defaults
  but none of the pipeline, tests/cli/test_startup.py);
- ``pcmapq inspect --scans ...``: MME, MPV and MOM of map-metrics' depth data (28 clouds,
  103,975 points, radius 0.2 m, MOM's planes from ``orth_subset/orth-0091.npy``), the command
  docs/commands/inspect.md gives;
- map-metrics' whole run: a fresh Python that imports map-metrics, reads the clouds with Open3D
  and the poses as its own tests do, and computes its ``mme``, ``mpv`` and ``mom``
  (``DepthConfig``). It runs when map-metrics imports, as bench_noref.py says (MAP_METRICS_SRC).

Every round runs each of them once, in turn, so that the load of other processes weighs on all
alike; the table gives the median wall time over ``--repeat`` rounds with its range, the peak
RSS (the child's ``ru_maxrss``), and map-metrics' run divided by each (the median of the rounds'
ratios). Numba's compiled loops are cached on disk, so one run of the inspect command before
the rounds compiles them if the cache is cold (once per install). ``--baseline SRC``
also times the pcmapq commands from another source tree (``git archive`` of another commit,
say) in the same rounds, labelled "(baseline)".
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEPTH = ROOT.parent / "shared" / "data" / "map-metrics" / "depth"
#: Exit code of the map-metrics child when map-metrics does not import.
NOT_RUN = 3

THEIRS = r"""
import sys
from bench.bench_noref import map_metrics, map_metrics_inputs
mm = map_metrics()
if mm is None:
    sys.exit(int(sys.argv[1]))
from map_metrics.config import DepthConfig
pcs, ts, orth = map_metrics_inputs()
print(mm.mme(pcs, ts, DepthConfig), mm.mpv(pcs, ts, DepthConfig),
      mm.mom(pcs, ts, orth, DepthConfig))
"""


def inspect_args(out: Path) -> list[str]:
    """``pcmapq inspect`` on the depth data, writing its JSON to ``out``."""
    return ["inspect", "--scans", str(DEPTH / "pcs"), "--poses", str(DEPTH / "poses"),
            "--radius", "0.2", "--orth-subset", str(DEPTH / "orth_subset/orth-0091.npy"),
            "--orth-pose", str(DEPTH / "poses/pose-0091.txt"), "--json", str(out), "--quiet"]


def timed(cmd: list[str], env: dict[str, str]) -> tuple[float, float, int, str]:
    """Run ``cmd`` in a fresh process: wall seconds, peak RSS MB, exit code, its output."""
    with tempfile.TemporaryFile() as out:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, env=env)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        return wall, usage.ru_maxrss / 1024, proc.returncode, out.read().decode(errors="replace")


def environment(path: Path) -> dict[str, str]:
    """This environment with ``path`` first on PYTHONPATH."""
    rest = os.environ.get("PYTHONPATH")
    return dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, (str(path), rest))))


def ratio_of(theirs: list[float], ours: list[float]) -> float:
    """The median over the rounds of map-metrics' time divided by ours."""
    return statistics.median(t / w for t, w in zip(theirs, ours, strict=True))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="rounds (default 3)")
    ap.add_argument("--skip-theirs", action="store_true", help="do not run map-metrics")
    ap.add_argument("--baseline", type=Path, help="another pcmapq source tree to time too")
    args = ap.parse_args()
    if not DEPTH.exists():
        sys.exit(f"{DEPTH} is absent: nothing to measure")
    work = Path(tempfile.mkdtemp())
    python = sys.executable
    trees = {"": ROOT / "src"}
    if args.baseline is not None:
        trees[" (baseline)"] = args.baseline.resolve()
    runs: dict[str, tuple[list[str], dict[str, str]]] = {
        "`python -c pass`": ([python, "-c", "pass"], dict(os.environ))}
    for index, (label, src) in enumerate(trees.items()):
        env = environment(src)
        pcmapq = [python, "-m", "pcmapq"]
        runs |= {f"`pcmapq --version`{label}": (pcmapq + ["--version"], env),
                 f"`pcmapq --help`{label}": (pcmapq + ["--help"], env),
                 f"`pcmapq inspect --help`{label}": (pcmapq + ["inspect", "--help"], env),
                 f"`pcmapq eval --help`{label}": (pcmapq + ["eval", "--help"], env),
                 f"`pcmapq inspect` on the depth data{label}":
                     (pcmapq + inspect_args(work / f"depth{index}.json"), env)}
        timed(runs[f"`pcmapq inspect` on the depth data{label}"][0], env)  # Numba's cache
    theirs = "map-metrics' whole run"
    if not args.skip_theirs:
        runs[theirs] = ([python, "-c", THEIRS, str(NOT_RUN)], environment(ROOT))
    walls: dict[str, list[float]] = {name: [] for name in runs}
    peaks: dict[str, float] = dict.fromkeys(runs, 0.0)
    outputs: dict[str, str] = {}
    for _ in range(args.repeat):
        for name, (cmd, env) in list(runs.items()):
            wall, peak, code, text = timed(cmd, env)
            if name == theirs and code == NOT_RUN:
                print(f"map-metrics not run: {text.strip()}", file=sys.stderr)
                del runs[name], walls[name], peaks[name]
                continue
            if code != 0:
                sys.exit(f"{' '.join(cmd)} failed (exit {code}):\n{text}")
            walls[name].append(wall)
            peaks[name] = max(peaks[name], peak)
            outputs[name] = text
    rows = ["| run | wall s, median (range) | peak RSS MB | map-metrics' run / this |",
            "|---|---|---|---|"]
    for name, values in walls.items():
        ratio = "" if theirs not in walls else f"{ratio_of(walls[theirs], values):.1f}"
        rows.append(f"| {name} | {statistics.median(values):.2f} ({min(values):.2f}-"
                    f"{max(values):.2f}) | {peaks[name]:.0f} | {ratio} |")
    ours = json.loads((work / "depth0.json").read_text())["cloud"]
    rows += ["", f"{args.repeat} rounds. pcmapq: MME {ours['mme']}, MPV {ours['mpv']}, "
             f"MOM {ours['mom']}"
             + (f"; map-metrics: MME, MPV, MOM {outputs[theirs].split()[-3:]}"
                if theirs in outputs else "; map-metrics not run") + "."]
    print("\n".join(rows))


if __name__ == "__main__":
    main()
