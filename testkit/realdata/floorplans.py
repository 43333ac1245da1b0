"""Floor plans: two SLAM maps against hand-drawn plans, scale and rotation unknown, with the
answers a survey gave when the cases were added."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pcmapq.io import Thresholds
from pcmapq.results.result import Result
from pcmapq.settings import AlignmentConfig, Settings, SourceConfig

from ..runs import Run, timed_evaluate, yaw_error

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
