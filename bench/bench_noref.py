"""No-reference metrics (MME, MPV, MOM): pcmapq against map-metrics, side by side; a markdown
table.

    python bench/bench_noref.py [--repeat 3] [--large 10000000] [--skip-theirs]

1. map-metrics' depth test data (../shared/data/map-metrics/depth, 28 clouds, 104k points;
   radius 0.2 m, more than 5 neighbours; MOM with its ``orth_subset/orth-0091.npy``): the
   figures and the time of each metric, pcmapq (``scores`` gives MME and MPV in one pass, so
   both rows show that pass) and map-metrics' own code, run in this process. map-metrics runs
   when ``import map_metrics`` works: its Python package (0.0.4, MobileRoboticsSkoltech/
   map-metrics, master) on PYTHONPATH, or a checkout named by MAP_METRICS_SRC, with networkx
   and scikit-learn importable. PyPI's ``map-metrics`` 0.0.5 is its C++ rewrite, built for
   Python 3.6-3.10 only; nothing of it is copied here. Its ``nptyping`` 1.x does not import
   under NumPy 2 and is used only in its type hints, so a stand-in is provided when the real
   one fails.
2. A synthetic 10-million-point map (a ground and walls, 32 points per square metre, 2 cm
   noise; radius 1.0 m, LiDAR's preset) scored in a fresh process: seconds and peak RSS
   (VmHWM).

Seconds are wall clock, the best of ``--repeat`` runs for pcmapq and of one run for
map-metrics (tens of seconds each); CPU seconds beside them (all threads). The whole commands,
start-up included, each in a fresh process: bench_startup.py.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
import types
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEPTH = ROOT.parent / "shared" / "data" / "map-metrics" / "depth"
RADIUS, MIN_KNN = 0.2, 5

CHILD = r"""
import sys, time
import numpy as np
from pcmapq.metrics import noref
n = int(sys.argv[1])
rng = np.random.default_rng(0)
ground = int(n * 0.7)
side = np.sqrt(ground / 32.0)
pts = np.empty((n, 3))
pts[:ground, :2] = rng.uniform(0, side, (ground, 2))
pts[:ground, 2] = rng.normal(0, 0.02, ground)
walls = n - ground
k = rng.integers(0, 20, walls)
along = rng.uniform(0, side, walls)
pts[ground:, 0] = np.where(k < 10, (k % 10) * side / 10 + rng.normal(0, 0.02, walls), along)
pts[ground:, 1] = np.where(k < 10, along, (k % 10) * side / 10 + rng.normal(0, 0.02, walls))
pts[ground:, 2] = rng.uniform(0, walls / (32.0 * 20 * side), walls)
def status_mb(key):
    line = next(x for x in open("/proc/self/status") if x.startswith(key + ":"))
    return int(line.split()[1]) / 1024
before = status_mb("VmRSS")
t, c = time.perf_counter(), time.process_time()
s = noref.scores(pts, 1.0, 5)
print(n, time.perf_counter() - t, time.process_time() - c, status_mb("VmHWM"), before, s.mme,
      s.mpv, s.mpv_points, round(side, 1))
"""


def _timed(fn: Callable[[], object], repeat: int) -> tuple[object, float, float]:
    best = (None, float("inf"), 0.0)
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        value = fn()
        wall, cpu = time.perf_counter() - t, time.process_time() - c
        if wall < best[1]:
            best = (value, wall, cpu)
    return best


def map_metrics() -> types.ModuleType | None:
    """map-metrics' ``metrics`` module, or None (saying why on stderr)."""
    src = os.environ.get("MAP_METRICS_SRC")
    if src:
        sys.path.insert(0, src)
    try:
        import nptyping  # noqa: F401
    except Exception:  # nptyping 1.x fails under NumPy 2: annotations only, a stand-in
        class _Any:
            def __getitem__(self, item: object) -> _Any:
                return self

        sys.modules["nptyping"] = types.SimpleNamespace(NDArray=_Any())  # type: ignore[assignment]
    try:
        import map_metrics.metrics as mm
        from map_metrics.utils import orthogonal  # noqa: F401
    except Exception as exc:
        print(f"map-metrics not run: cannot import it ({exc}); set MAP_METRICS_SRC to a "
              "checkout of MobileRoboticsSkoltech/map-metrics (with networkx and scikit-learn)",
              file=sys.stderr)
        return None
    if not hasattr(mm, "mme"):
        print("map-metrics not run: this map_metrics has no Python mme()", file=sys.stderr)
        return None
    return mm


def map_metrics_inputs() -> tuple[list, list[np.ndarray], list]:
    """The depth data as map-metrics' own tests load it: the clouds read by Open3D, the poses,
    and MOM's orthogonal subset placed by map-metrics' ``read_orthogonal_subset``."""
    import open3d as o3d
    from map_metrics.utils.orthogonal import read_orthogonal_subset

    names = sorted(os.listdir(DEPTH / "pcs"))
    pcs = [o3d.io.read_point_cloud(str(DEPTH / "pcs" / n)) for n in names]
    ts = [np.loadtxt(DEPTH / "poses" / n, usecols=range(4))
          for n in sorted(os.listdir(DEPTH / "poses"))]
    orth = read_orthogonal_subset(DEPTH / "orth_subset/orth-0091.npy",
                                  DEPTH / "poses/pose-0091.txt", ts)
    return pcs, ts, orth


def depth_rows(repeat: int, theirs: bool) -> list[str]:
    from pcmapq.mapping.poses import read_pose_matrix, read_poses
    from pcmapq.mapping.reference import posed_map
    from pcmapq.metrics import noref, posed

    points = posed_map(DEPTH / "pcs", read_poses(DEPTH / "poses"))
    poses = read_poses(DEPTH / "poses")
    planes = posed.place_subset(posed.read_orthogonal_subset(DEPTH / "orth_subset/orth-0091.npy"),
                                read_pose_matrix(DEPTH / "poses/pose-0091.txt"), poses[0])
    s, wall, cpu = _timed(lambda: noref.scores(points, RADIUS, MIN_KNN), repeat)
    m, m_wall, m_cpu = _timed(lambda: noref.mom(points, planes, RADIUS), repeat)
    ours = {"MME": (s.mme, wall, cpu), "MPV": (s.mpv, wall, cpu), "MOM": (m, m_wall, m_cpu)}
    mm = map_metrics() if theirs else None
    rows = [f"{len(points)} points. pcmapq's MME and MPV come from one pass (its time in both "
            "rows).", "",
            "| metric | pcmapq | map-metrics | difference | pcmapq s (CPU) | map-metrics s (CPU) "
            "| times faster (wall) |", "|---|---|---|---|---|---|---|"]
    if mm is not None:
        from map_metrics.config import DepthConfig

        pcs, ts, orth = map_metrics_inputs()
        calls = {"MME": lambda: mm.mme(pcs, ts, DepthConfig),
                 "MPV": lambda: mm.mpv(pcs, ts, DepthConfig),
                 "MOM": lambda: mm.mom(pcs, ts, orth, DepthConfig)}
    total = [0.0, 0.0]
    for name, (value, w, c) in ours.items():
        if mm is None:
            rows.append(f"| {name} | {value:.9g} | not run | | {w:.3f} ({c:.2f}) | | |")
            continue
        theirs_v, tw, tc = _timed(calls[name], 1)
        total[0] += tw
        total[1] += w if name != "MPV" else 0.0  # one pass gives MME and MPV
        rows.append(f"| {name} | {value:.9g} | {float(theirs_v):.9g} | "
                    f"{abs(value - float(theirs_v)):.1e} | {w:.3f} ({c:.2f}) | "
                    f"{tw:.2f} ({tc:.2f}) | {tw / w:.0f} |")
    if mm is not None:
        rows.append(f"| all three | | | | {total[1]:.3f} | {total[0]:.2f} | "
                    f"{total[0] / total[1]:.0f} |")
    return rows


def large_rows(n: int) -> list[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    out = subprocess.run([sys.executable, "-c", CHILD, str(n)], capture_output=True, text=True,
                         env=env, check=True).stdout.split()
    n, wall, cpu, peak, before, mme, mpv, used, side = out
    return ["", f"Synthetic map: {int(n):,} points (ground {side} m square and 20 walls, "
            "32 points/m^2, 2 cm noise), radius 1.0 m, min_knn 5:", "",
            "| points | seconds (CPU) | peak RSS MB | RSS before MB | MME | MPV m^2 "
            "| points used |",
            "|---|---|---|---|---|---|---|",
            f"| {int(n):,} | {float(wall):.1f} ({float(cpu):.1f}) | {float(peak):.0f} | "
            f"{float(before):.0f} | {float(mme):.4f} | {float(mpv):.3g} | {int(used):,} |"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--large", type=int, default=10_000_000, help="0: skip the synthetic map")
    ap.add_argument("--skip-theirs", action="store_true", help="do not run map-metrics")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT / "src"))
    rows: list[str] = []
    if DEPTH.exists():
        rows += depth_rows(args.repeat, not args.skip_theirs)
    else:
        print(f"{DEPTH} is absent: the depth comparison is skipped", file=sys.stderr)
    if args.large:
        rows += large_rows(args.large)
    print("\n".join(rows))


if __name__ == "__main__":
    main()
