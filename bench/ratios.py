"""pcmapq's speed and memory as ratios to a floor or a peer measured in the same run, so that a
busy machine slows both sides alike and cannot hide a regression (``python -m bench``).

Each case runs its commands in fresh processes (wall seconds and peak memory of the child, the
processes it starts counted: :func:`bench.bench_clouds.measured`), alternating the two sides
and keeping each side's best of ``repeat`` runs:

- ``noref``: ``pcmapq eval`` by default against ``--no-noref`` (the price of the default
  no-reference block) on the shipped sample, KITTI 00's 20-scan pair and a 10 M-point cloud;
- ``rooms``: ``pcmapq eval`` by default against ``--detectors harris,hough,sift`` (the price of
  the rooms detector; under a fifth of the evaluation's time is a ratio under 1.25) on the
  shipped sample, a Halmstad map against its building's layout and the campus grid pair;
- ``kitti``: ``pcmapq eval`` of KITTI 00's 20-scan KISS-ICP map against the map from its
  reference poses, against its floor: a process that imports Open3D, reads both clouds and
  downsamples them at the registration's 0.3 m voxel;
- ``clouds``: ``pcmapq eval`` of a 10 M-point cloud against its plan, against Open3D reading
  it and downsampling it at 0.05 m (:mod:`bench.bench_clouds`);
- ``campus``: the ``size`` x ``size`` campus grid pair against OpenCV reading both images and
  one distance transform (:mod:`bench.bench_grids`);
- ``structures``: ``pcmapq eval`` by default against ``--no-structures`` (the price of the 3D
  structures) on the synthetic building of :mod:`testkit.building3d` and KITTI 00's 20-scan
  pair;
- ``peer3d``: ``pcmapq eval`` of KITTI 00's 20 scans pitched 0.2 degrees a scan against their
  reference map, against CloudAnalyzer's ``ca compare`` + ``ca map-evaluate`` on the same pair,
  medians of three runs (:mod:`bench.bench_peer3d`);
- ``large3d``, and ``large3d50`` (opt-in: run only when named): issue 57's bounds on a pair
  of 3D clouds of 10 M points each, and of 50 M (:mod:`bench.bench_large3d`).

Inputs are built once into a cache folder outside the repository (``--cache``); cases whose
data (``../shared/data``) is absent are skipped with the reason.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path

from bench import large_grid
from bench.bench_clouds import FLOOR_CHILD as CLOUD_FLOOR
from bench.bench_clouds import measured, write_case
from bench.bench_grids import FLOOR_CHILD as GRID_FLOOR
from bench.timing import Ratio, best, eval_cmd, paired, written
from pcmapq.features import DEFAULT_DETECTORS
from testkit.paths import SAMPLE, SHARED_DATA
from testkit.realdata.halmstad import PLAN_RESOLUTION, halmstad_truth
from testkit.realdata.halmstad import paths as halmstad_paths

#: A ratio worse than its stored value by more than this share fails ``--check``.
TOLERANCE = 0.20

KITTI_FLOOR = r"""
import json, sys, time
start = time.perf_counter()
import open3d as o3d
for path in sys.argv[1:3]:
    o3d.io.read_point_cloud(path).voxel_down_sample(float(sys.argv[3]))
print(json.dumps({"seconds": time.perf_counter() - start}))
"""


def kitti_pair(cache: Path) -> tuple[Path, Path] | None:
    """KITTI 00's first 20 scans: the KISS-ICP map and the map of the reference poses, as
    ``pcmapq map`` builds them, written once into ``cache``; None without the data."""
    data = SHARED_DATA / "kitti00"
    if not (data / "velodyne").is_dir():
        return None

    def write(folder: Path) -> None:
        from bench.validation.kitti import kiss_map, reference_map
        from pcmapq.io.writers import write_cloud

        write_cloud(folder / "kiss.ply", kiss_map(data, 20)[0])
        write_cloud(folder / "ref.ply", reference_map(data, 20)[0])

    folder = written(cache / "kitti20", write)
    return folder / "kiss.ply", folder / "ref.ply"


def cloud_case(cache: Path, millions: int = 10) -> tuple[Path, Path]:
    """:mod:`bench.bench_clouds`' campus cloud of ``millions`` M points and its plan, once."""
    folder = written(cache / f"cloud_{millions}M",
                     lambda part: write_case(part, millions * 1_000_000))
    return folder / "cloud.ply", folder / "truth.yaml"


def grid_case(cache: Path, size: int) -> Path:
    """:mod:`bench.large_grid`'s ``size`` x ``size`` campus grid pair, written once."""
    return written(cache / f"grid_{size}", lambda part: large_grid.write_case(part, size))


def noref(cache: Path, repeat: int) -> list[Ratio]:
    """The default no-reference block's price: eval by default / eval --no-noref."""
    pairs = [("sample", SAMPLE / "scan.ply", SAMPLE / "truth.yaml")]
    kitti = kitti_pair(cache)
    if kitti is not None:
        pairs.append(("KITTI 20 scans", *kitti))
    pairs.append(("10 M points", *cloud_case(cache)))
    out = []
    for name, map_path, truth in pairs:
        on, off = paired(eval_cmd(map_path, truth, cache / "on.json"),
                         eval_cmd(map_path, truth, cache / "off.json", "--no-noref"), repeat)
        out += [Ratio(f"noref/{name}/time", on[0] / off[0], f"default {on[0]:.1f} s",
                      f"--no-noref {off[0]:.1f} s", 1.15),
                Ratio(f"noref/{name}/memory", on[1] / off[1], f"default {on[1]:.2f} GB",
                      f"--no-noref {off[1]:.2f} GB", 1.10)]
    return out


#: The detectors but the rooms.
WITHOUT_ROOMS = ",".join(d for d in DEFAULT_DETECTORS if d != "rooms")
#: The Halmstad map of the rooms case (the one with the most truth rooms matched, docs/
#: validation.md), read as the Halmstad validation reads it: scale unknown.
HALMSTAD_MAP = "E5_07"


def rooms(cache: Path, repeat: int) -> list[Ratio]:
    """The rooms detector's price: eval by default / eval without the rooms detector."""
    cases = [("sample", SAMPLE / "scan.ply", SAMPLE / "truth.yaml", ())]
    if (SHARED_DATA / "halmstad").is_dir():
        map_path, layout = halmstad_paths(SHARED_DATA, HALMSTAD_MAP)
        folder = cache / "halmstad"
        folder.mkdir(exist_ok=True)
        cases.append((f"Halmstad {HALMSTAD_MAP}", map_path, halmstad_truth(layout, folder),
                      ("--scale", "auto", "--truth-resolution", str(PLAN_RESOLUTION))))
    else:
        print(f"rooms: Halmstad skipped, {SHARED_DATA / 'halmstad'} is absent", file=sys.stderr)
    grid = grid_case(cache, 8000)
    cases.append(("campus 8000^2", grid / "map.yaml", grid / "truth.yaml", ()))
    out = []
    for name, map_path, truth, extra in cases:
        with_rooms, without = paired(
            eval_cmd(map_path, truth, cache / "on.json", *extra),
            eval_cmd(map_path, truth, cache / "off.json", *extra, "--detectors", WITHOUT_ROOMS),
            repeat)
        out.append(Ratio(f"rooms/{name}/time", with_rooms[0] / without[0],
                         f"default {with_rooms[0]:.1f} s",
                         f"--detectors {WITHOUT_ROOMS} {without[0]:.1f} s", 1.25))
    return out


def building_pair(cache: Path) -> tuple[Path, Path]:
    """The synthetic building of :mod:`testkit.building3d` and its moved map, written once."""
    def write(folder: Path) -> None:
        from pcmapq.io.writers import write_cloud
        from testkit import building3d

        write_cloud(folder / "truth.ply", building3d.cloud(building3d.faces(), seed=1))
        write_cloud(folder / "moved.ply", building3d.moved_map())

    folder = written(cache / "building3d", write)
    return folder / "moved.ply", folder / "truth.ply"


def structures(cache: Path, repeat: int) -> list[Ratio]:
    """The 3D structures' price: eval by default / eval --no-structures, on the synthetic
    building and on KITTI 00's 20-scan pair (at the structures' voxel for outdoor maps,
    0.3 m, and at the default, 0.1 m)."""
    cases = [("building", *building_pair(cache), ())]
    kitti = kitti_pair(cache)
    if kitti is not None:
        cases += [("KITTI 20 scans", *kitti, ("--structures-voxel", "0.3")),
                  ("KITTI 20 scans, 0.1 m voxel", *kitti, ())]
    else:
        print("structures: KITTI skipped, ../shared/data/kitti00 is absent", file=sys.stderr)
    out = []
    for name, map_path, truth, extra in cases:
        on, off = paired(eval_cmd(map_path, truth, cache / "on.json", *extra),
                         eval_cmd(map_path, truth, cache / "off.json", *extra,
                                  "--no-structures"), repeat)
        out.append(Ratio(f"structures/{name}/time", on[0] / off[0],
                         f"default{' ' + ' '.join(extra) if extra else ''} {on[0]:.1f} s",
                         f"--no-structures {off[0]:.1f} s"))
    return out


def kitti(cache: Path, repeat: int) -> list[Ratio]:
    """KITTI 00's 20-scan pair by default against Open3D reading and downsampling both."""
    pair = kitti_pair(cache)
    if pair is None:
        print("kitti: skipped, ../shared/data/kitti00 is absent", file=sys.stderr)
        return []
    ours, floor = paired(eval_cmd(*pair, cache / "kitti.json"),
                         [sys.executable, "-c", KITTI_FLOOR, *map(str, pair), "0.3"], repeat)
    return [Ratio("kitti/time", ours[0] / floor[0], f"pcmapq eval {ours[0]:.1f} s",
                  f"Open3D read + 0.3 m voxel {floor[0]:.1f} s"),
            Ratio("kitti/memory", ours[1] / floor[1], f"pcmapq eval {ours[1]:.2f} GB",
                  f"Open3D read + 0.3 m voxel {floor[1]:.2f} GB")]


def clouds(cache: Path, repeat: int) -> list[Ratio]:
    """A 10 M-point cloud against its plan, against Open3D reading it and voxelising it."""
    cloud, truth = cloud_case(cache)
    ours, floor = paired(eval_cmd(cloud, truth, cache / "cloud.json"),
                         [sys.executable, "-c", CLOUD_FLOOR, str(cloud), "0.05"], repeat)
    return [Ratio("clouds 10 M/time", ours[0] / floor[0], f"pcmapq eval {ours[0]:.1f} s",
                  f"Open3D read + 0.05 m voxel {floor[0]:.1f} s (process)"),
            Ratio("clouds 10 M/memory", ours[1] / floor[1], f"pcmapq eval {ours[1]:.2f} GB",
                  f"Open3D read + 0.05 m voxel {floor[1]:.2f} GB")]


def campus(cache: Path, repeat: int, size: int = 8000) -> list[Ratio]:
    """The campus grid pair against OpenCV reading both images and one distance transform
    (timed inside its process, as bench_grids does)."""
    case = grid_case(cache, size)
    floors = [json.loads(measured([sys.executable, "-c", GRID_FLOOR, str(case / "truth.png"),
                                   str(case / "map.png")])[2].strip().splitlines()[-1])
              ["seconds"] for _ in range(repeat)]
    seconds, gb = best(eval_cmd(case / "map.yaml", case / "truth.yaml", cache / "grid.json"),
                       repeat)
    return [Ratio(f"campus {size}^2/time", seconds / min(floors), f"pcmapq eval {seconds:.1f} s, "
                  f"{gb:.2f} GB", f"OpenCV read x 2 + distance transform {min(floors):.2f} s",
                  40.0)]


def peer3d(cache: Path, repeat: int) -> list[Ratio]:
    """KITTI 00's pitched pair against CloudAnalyzer (:func:`bench.bench_peer3d.case`)."""
    from bench.bench_peer3d import case  # it builds its Ratios from this module

    return case(cache, repeat)


def large3d(cache: Path, repeat: int) -> list[Ratio]:
    """:func:`bench.bench_large3d.large3d` (loaded when run)."""
    from bench import bench_large3d

    return bench_large3d.large3d(cache, repeat)


def large3d50(cache: Path, repeat: int) -> list[Ratio]:
    """:func:`bench.bench_large3d.large3d50` (loaded when run)."""
    from bench import bench_large3d

    return bench_large3d.large3d50(cache, repeat)


#: name -> case; each returns its ratios.
CASES: dict[str, Callable[[Path, int], list[Ratio]]] = {
    "noref": noref, "rooms": rooms, "kitti": kitti, "clouds": clouds, "campus": campus,
    "structures": structures, "peer3d": peer3d, "large3d": large3d, "large3d50": large3d50,
}
#: Cases run only when named (``--only``): each takes many minutes.
OPT_IN = ("large3d50",)


def compare(found: list[Ratio], stored: dict[str, float]) -> list[str]:
    """The ratios that worsened by more than TOLERANCE against ``stored``, one line each."""
    return [f"{r.name}: {r.value:.2f} against {stored[r.name]:.2f} stored (+"
            f"{100 * (r.value / stored[r.name] - 1):.0f} %)"
            for r in found if r.name in stored and r.value > stored[r.name] * (1 + TOLERANCE)]


def table(found: list[Ratio], shown: str = "") -> str:
    """The ratios' markdown table: the rows of ``shown`` (a table this function wrote) with
    those measured now replaced, in their places, and the new ones after them."""
    rows = {r.name: r.row() for r in found}
    kept = [line for line in shown.splitlines() if line.startswith("| ") and
            not line.startswith("| ratio |")]
    names = [line.split("|")[1].strip() for line in kept]
    body = [rows.pop(name, line) for name, line in zip(names, kept, strict=True)]
    return "\n".join(["| ratio | value | target | pcmapq | floor or peer |",
                      "|---|---:|---:|---|---|", *body, *rows.values()])
