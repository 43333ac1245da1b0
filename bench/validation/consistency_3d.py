"""Where a 3D map bends: does the 3D consistency map (each ground tile of a map registered to
the truth on its own in 3D, :mod:`pcmapq.align.regions3d`) report the vertical offset a known
drift put there?

KITTI 00's first 20 scans (about 16 m of road), each cut to 12 m of range, placed at the
reference poses (the truth) and at poses that drift vertically (the map), both built as
``pcmapq map --poses`` builds them but written without their points' scans (so that the
regions are tiles), and scored as ``pcmapq eval map.ply truth.ply``:

- pitch: each step's motion turned about the car's lateral axis by a further ``level``
  degrees, as a pitch drift integrates (scan k pitched by k x level, the run bending down);
- lower: scan k lowered by k x ``level`` metres.

Every map point's true place is known (the same beam at the reference pose), so each region's
expected dz is the mean vertical error of its points once the map is placed as the evaluation's
3D registration placed it (in the truth's levelled frame, each point at the 0.3 m voxel the
regions are taken at). The 12 m range makes the run longer than a scan's reach: with KITTI's
full range every tile holds points of all 20 scans, and a drift blurs the map rather than bends
it.

    python -m bench.validation --only consistency_3d
"""

from __future__ import annotations

from pathlib import Path

from testkit.realdata.bends3d import LADDERS, RANGE_M, SCANS, WITHIN_M, WITHIN_SHARE, Rung, measure

from .common import Case, Record, Section


def cases(data: Path) -> list[Case]:
    return [Case(f"consistency-3d-{kind}-{level:g}",
                 lambda kind=kind, level=level: measure(data / "kitti00", kind, level))
            for kind, levels in LADDERS for level in levels]


def section(data: Path, record: Record) -> Section:
    rungs: list[Rung] = [case.run(record) for case in cases(data)]
    rows = [f"| {g.kind} | {g.level:g} | {g.injected_m:.3f} | {g.fitness:.2f} | "
            f"{g.held} / {g.regions} | ({g.far_at[0]:.1f}, {g.far_at[1]:.1f}) | "
            f"{g.expected_m:.3f} | {g.reported_m:.3f} | {'yes' if g.within else '**no**'} | "
            f"{g.largest_m:.3f} | {'yes' if g.same_region else '**no**'} | "
            f"{g.median_error_m:.3f} / {g.max_error_m:.3f} | {g.seconds:.0f} |" for g in rungs]
    return Section("\n".join([
        "## Where a 3D map bends: KITTI 00 drifting vertically", "",
        f"The first {SCANS} scans of `kitti00`, each cut to {RANGE_M:g} m of range, at KITTI's "
        "reference poses (the truth) and at poses that drift vertically (the map): *pitch*: "
        "each step's motion turned about the car's lateral axis by a further *level* degrees "
        "(scan k pitched by k x level, the run bending down, as a pitch drift integrates); "
        "*lower*: scan k lowered by k x *level* metres. Both built as `pcmapq map --poses` "
        "builds them but written without their points' scans, so that the regions are tiles, "
        "and scored as `pcmapq eval map.ply truth.ply` (`--force`, no detectors, "
        "no no-reference figures), with the 3D consistency map's defaults (8 m tiles, the "
        "3D registration's 0.3 m voxel; `consistency_3d` in the JSON, `--regions-3d`). "
        "Each map point's true place is known (the same beam at the reference pose), so each "
        "region's expected dz is the mean vertical error of its points once the map is placed "
        "as the evaluation's 3D registration placed it (in the truth's levelled frame). "
        "*injected*: the last scan's vertical offset as drifted; the global registration takes "
        "up part of it (a rigid tilt and lift of the whole map), so a region is expected to "
        "show what remains. *far region*: the held region with the largest expected |dz| "
        f"(centroid x, y); *within*: reported within {WITHIN_M:g} m + "
        f"{WITHIN_SHARE:.0%} of the injected offset of the expected. *largest*: the held "
        "region with the largest reported |dz|, and whether it is the far region. The "
        f"{RANGE_M:g} m range makes the run longer than a scan's reach: with KITTI's full "
        "range every tile holds points of all 20 scans and a drift blurs the map rather than "
        "bends it (a map lowered scan by scan then shows doubled ground, not a sink).", "",
        "| drift | level | injected dz (m) | 3D fitness | held / regions | far region (m) | "
        "expected dz (m) | reported dz (m) | within | largest dz (m) | same region | "
        "median / max error, held (m) | time (s) |",
        "| --- | ---: | ---: | ---: | ---: | --- | ---: | ---: | --- | ---: | --- | ---: | "
        "---: |", *rows, "",
        "A pitch drift bends the run; the registration fits its middle and leaves both ends "
        "too low, most at the far end, where the largest reported |dz| lies, within a few "
        "centimetres of the expected. Lowering scan by scan is taken up almost whole by the "
        "registration's tilt of the map (the scans overlap along the 16 m): what remains is a "
        "few centimetres, within the regions' own error (the last column), and the regions "
        "report it so; the region with the largest reported |dz| is then as likely another "
        "as the expected one.",
    ]))
