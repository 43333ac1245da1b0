"""Gazebo: a SLAM map of unknown pixel size against the rendered world (529 px per metre),
scored with the scale estimated, and the bound its accuracy must meet."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from pcmapq.settings import AlignmentConfig, Settings, SourceConfig

from ..runs import Run, timed_evaluate

#: Gazebo truth: 529 px per metre (../shared/README.md).
RESOLUTION = 1.0 / 529.0
#: Bound of the check (tests/realdata/test_validation.py): mean accuracy, metres.
BOUND_M = 0.08
SETTINGS = Settings(truth=SourceConfig(resolution=RESOLUTION),
                    alignment=AlignmentConfig(scale=True))
MAP, TRUTH = "SLAM_Gen_Map.png", "Ground_Truth.png"


def run(data: Path, footprint: str = "auto") -> Run:
    """The Gazebo SLAM map scored against its truth, scale estimated."""
    folder = data / "gazebo"
    settings = replace(SETTINGS, footprint=replace(SETTINGS.footprint, rule=footprint))
    return timed_evaluate(folder / MAP, folder / TRUTH, settings)
