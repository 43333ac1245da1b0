"""Issue 57's bounds on a large pair of 3D clouds (:mod:`testkit.town3d`'s town, written once
into the cache by :mod:`bench.large_3d`), as ratios of :mod:`bench.ratios`
(``python -m bench --only large3d``):

- ``large3d``: ``pcmapq eval map.ply truth.ply`` of the 10 M-point pair by default against the
  same run without the 3D figures of two clouds: ``--no-structures``, and AWD/SCS and the 3D
  consistency map left out (:data:`WITHOUT_CHILD`: no option turns them off, so the child
  runs the command with ``scoring.in_one_frame_3d`` answering no and ``scoring.regions_3d``
  finding nothing). Time and peak memory ratios, each at most 1.5.
- ``large3d50`` (opt-in, not run by default: a run takes many minutes): the 50 M-point pair by
  default, its peak memory over 8 GB (at most 1), and its wall seconds beside it.

Each run is a fresh process; wall seconds and its peak memory, the processes it starts
counted (:func:`bench.bench_clouds.measured`).
"""

from __future__ import annotations

import sys
from pathlib import Path

from bench import large_3d
from bench.bench_clouds import measured
from bench.timing import Ratio, eval_cmd, paired, written

#: The 50 M case's bound, GB as :func:`bench.bench_clouds.measured` gives them (issue 57).
BOUND_GB = 8.0

#: ``pcmapq eval ...`` without AWD/SCS and the 3D consistency map (add --no-structures).
WITHOUT_CHILD = r"""
import os, sys
from pcmapq.cli import BLAS_THREADS, main
os.environ.setdefault("OPENBLAS_NUM_THREADS", BLAS_THREADS)
import pcmapq.evaluation.scoring as scoring
scoring.in_one_frame_3d = lambda *args: False
scoring.regions_3d = lambda *args, **kwargs: None
sys.argv = ["pcmapq", *sys.argv[1:]]
main()
"""


def town_pair(cache: Path, millions: int) -> tuple[Path, Path]:
    """The map and truth clouds of ``millions`` M points each, written once into ``cache``."""
    folder = written(cache / f"town_{millions}M",
                     lambda part: large_3d.write_case(part, millions * 1_000_000))
    return folder / "map.ply", folder / "truth.ply"


def without_cmd(map_path: Path, truth: Path, out: Path) -> list[str]:
    """``pcmapq eval`` without the 3D figures of two clouds (module docstring)."""
    return [sys.executable, "-c", WITHOUT_CHILD, "eval", str(map_path), str(truth), "--json",
            str(out), "--no-structures"]


def large3d(cache: Path, repeat: int) -> list[Ratio]:
    """The 10 M pair with the 3D figures against without them: time and memory."""
    map_path, truth = town_pair(cache, 10)
    on, off = paired(eval_cmd(map_path, truth, cache / "on.json"),
                     without_cmd(map_path, truth, cache / "off.json"), repeat)
    return [Ratio("large3d 10 M/time", on[0] / off[0], f"default {on[0]:.0f} s",
                  f"without the 3D figures {off[0]:.0f} s", 1.5),
            Ratio("large3d 10 M/memory", on[1] / off[1], f"default {on[1]:.2f} GB",
                  f"without the 3D figures {off[1]:.2f} GB", 1.5)]


def large3d50(cache: Path, repeat: int) -> list[Ratio]:
    """The 50 M pair by default: its peak memory over the 8 GB bound (best of ``repeat``)."""
    map_path, truth = town_pair(cache, 50)
    runs = [measured(eval_cmd(map_path, truth, cache / "big.json"))[:2] for _ in range(repeat)]
    seconds, gb = min(r[0] for r in runs), min(r[1] for r in runs)
    return [Ratio("large3d 50 M/memory", gb / BOUND_GB, f"default {gb:.2f} GB, {seconds:.0f} s",
                  f"the bound, {BOUND_GB:g} GB", 1.0)]
