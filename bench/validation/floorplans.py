"""Floor plans: two SLAM maps against hand-drawn plans, scale and rotation unknown; the
vectorial figure of each."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pcmapq.io import Thresholds
from pcmapq.report.text import number
from pcmapq.results.result import Result
from pcmapq.settings import AlignmentConfig, Settings, SourceConfig

from .common import (
    ROS,
    Case,
    Record,
    Run,
    Section,
    commonest_greys,
    header,
    occupancy,
    q_p,
    row,
    timed_evaluate,
    yaw_error,
)

#: Assumed resolution of every plan image, metres per pixel.
PLAN_RESOLUTION = 0.05
#: 'recovered': yaw within this many degrees of the expected one, scale within this share of
#: the survey's.
YAW_TOLERANCE_DEG, SCALE_TOLERANCE = 5.0, 0.05


@dataclass(frozen=True)
class FloorPlan:
    """A SLAM map vs a plan. survey_scale: plan pixels per map pixel by a survey made when the
    case was added (the expected answer, an input here, not measured); yaw_deg: expected
    rotation; thresholds: map_server thresholds for the map, if ROS's do not fit
    (``--map-occupied-thresh`` ... on the command line)."""

    name: str
    case: str
    map_file: str
    plan_file: str
    survey_scale: float
    yaw_deg: float
    thresholds: Thresholds | None = None

    @property
    def figure(self) -> str:
        """Its figure's path relative to docs/."""
        return f"img/validation_{Path(self.map_file).stem}.png"


#: The Intel map's walls are grey 127 (p = 0.502, unknown under ROS's occupied_thresh 0.65) and
#: its unexplored area grey 230 (p = 0.098, free under ROS's free_thresh 0.196).
FLOORPLANS = (
    FloorPlan("Intel Research Lab", "floorplans-intel", "intel_map.png", "lab_intel.png",
              1.168, 180.0, Thresholds(occupied=0.4, free=0.05)),
    FloorPlan("Freiburg 079", "floorplans-freiburg79", "freiburg_building79.png",
              "Freiburg79_scan.png", 0.863, 0.0),
)


def floorplan_run(case: FloorPlan, data: Path) -> Run:
    """One SLAM map vs its plan: plan at PLAN_RESOLUTION, the map's scale estimated (it starts
    at the plan's resolution, so the scale is plan pixels per map pixel)."""
    folder = data / "floorplans"
    settings = Settings(alignment=AlignmentConfig(scale=True),
                        truth=SourceConfig(resolution=PLAN_RESOLUTION),
                        map=SourceConfig(thresholds=case.thresholds))
    return timed_evaluate(folder / case.map_file, folder / case.plan_file, settings)


def recovered(case: FloorPlan, result: Result) -> bool:
    """Yaw and scale within the tolerances of the expected ones."""
    tf = result.transform
    return (yaw_error(tf.yaw_deg, case.yaw_deg) < YAW_TOLERANCE_DEG
            and abs(tf.scale / case.survey_scale - 1.0) < SCALE_TOLERANCE)


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
            *(q_p(r, k) for k in ("harris", "hough", "sift")),
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
