"""Floor plans: two SLAM maps against hand-drawn plans, scale and rotation unknown; the
vectorial figure of each."""

from __future__ import annotations

from pathlib import Path

from pcmapq.report.text import number
from pcmapq.results.result import Result
from testkit.realdata.floorplans import (
    FLOORPLANS,
    PLAN_RESOLUTION,
    SCALE_TOLERANCE,
    YAW_TOLERANCE_DEG,
    floorplan_run,
    recovered,
)
from testkit.runs import Run

from .common import ROS, Case, Record, Section, commonest_greys, header, occupancy, q_p, row


def figure_png(result: Result, dpi: int = 80) -> bytes:
    """The vectorial figure of ``result`` as PNG bytes."""
    from pcmapq.report.plot import png_bytes, vectorial_figure

    return png_bytes(vectorial_figure(result), dpi=dpi)


def cases(data: Path) -> list[Case]:
    return [Case(c.case, lambda c=c: floorplan_run(c, data)) for c in FLOORPLANS]


def section(data: Path, record: Record) -> Section:
    """Each SLAM map vs its plan, and their figures."""
    lines, files = [], {}
    for plan, case in zip(FLOORPLANS, cases(data), strict=True):
        run: Run = case.run(record)
        r, tf = run.result, run.result.transform
        lines.append(row([
            plan.name, f"{tf.scale:.3f} ({plan.survey_scale:.3f})",
            f"{tf.yaw_deg:.1f} ({plan.yaw_deg:.0f})",
            "yes" if recovered(plan, r) else "**no**", number(r.alignment.fitness, 2),
            number(r.overlap.coverage, 2), number(r.overlap.confidence, 2),
            *(q_p(r, k) for k in ("harris", "hough", "sift", "rooms")),
            number(r.distances.accuracy.mean), number(r.distances.completeness.mean),
            f"{run.seconds:.1f}"]))
        files[plan.figure] = figure_png(r)
    intel = FLOORPLANS[0].thresholds
    wall, unexplored, _ = commonest_greys(data / "floorplans" / FLOORPLANS[0].map_file)
    return Section("\n".join([
        "## Floor plans: SLAM maps vs hand-drawn plans, scale and rotation unknown", "",
        "`floorplans/intel_map.png` vs `lab_intel.png` (walls drawn as black double outlines "
        "with a grey fill, RGBA) and `freiburg_building79.png` vs `Freiburg79_scan.png`. No "
        f"resolution is given: the plan is taken at {PLAN_RESOLUTION} m per pixel and the map's "
        "scale is estimated from the same start, so the scale is plan pixels per map pixel. "
        "`Settings(alignment=AlignmentConfig(scale=True), "
        f"truth=SourceConfig(resolution={PLAN_RESOLUTION}))`, no `force`. The Intel "
        f"map's commonest greys besides white are {wall}, its walls ({occupancy(wall)}: unknown "
        f"under ROS's occupied_thresh {ROS.occupied_thresh}), and {unexplored}, its "
        f"unexplored area ({occupancy(unexplored)}: free under ROS's free_thresh "
        f"{ROS.free_thresh}), so it is read with "
        f"`--map-occupied-thresh {intel.occupied} --map-free-thresh {intel.free}` "
        "(`Settings.map.thresholds`), no YAML. The Freiburg images read correctly with ROS's "
        "defaults. The survey scale and the expected yaw are the expected answers, set when the "
        "cases were added (constants of `bench/validation/floorplans.py`), not measured here.",
        "",
        header(["pair", "scale (survey)", "yaw deg (expected)", "recovered", "fitness",
                "coverage", "confidence", "Harris q / p", "Hough q / p", "SIFT q / p",
                "rooms q / p",
                "acc mean m", "comp mean m", "s"]),
        *lines, "",
        f"'recovered': yaw within {YAW_TOLERANCE_DEG:g} degrees of the expected one and scale "
        f"within {100 * SCALE_TOLERANCE:.0f} % of the survey's. The plans hold only the walls, the "
        "SLAM maps also furniture and clutter, so most map cells lie off the plan (fitness, "
        "precision and accuracy say so); the confidence (same place, below) is not misled by "
        "them.", "",
        *(f"![{p.name}: vectorial map]({p.figure}) ({len(files[p.figure]) // 1000} kB)"
          for p in FLOORPLANS),
    ]), files)
