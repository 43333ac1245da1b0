"""The library's calls for the commands that have no one function in the pipeline:
:func:`inspect` (``pcmapq inspect``) and :func:`track_quality` (``pcmapq track``, without its
files). Lengths in metres; frames: ``p_truth = s * R(yaw) * p_map + t``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pcmapq.evaluation.inspect_map import inspect_map
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.settings import TRACK_EVERY, NoRefConfig, Settings
from pcmapq.track import RunOptions, Tracked, plan_run, track_plan

__all__ = ["inspect", "track_quality"]


def inspect(map_path: str | Path, config: NoRefConfig | None = None,
            resolution: float | None = None) -> dict[str, Any]:
    """``pcmapq inspect``: the no-reference figures of one map (a cloud, image or CARMEN log;
    ``resolution``: metres per pixel of an image without YAML), as its JSON holds them."""
    source: OccupancyMap | PointMap = load_map(Path(map_path), resolution)
    return inspect_map(source, config or NoRefConfig())


def track_quality(run_path: str | Path, truth_path: str | Path, settings: Settings | None = None, *,
          every: int | None = TRACK_EVERY, every_m: float | None = None,
          poses: str | Path | None = None, reference_poses: str | Path | None = None,
          calib: str | Path | None = None) -> Tracked:
    """``pcmapq track``: the run's map scored every ``every`` scans (or ``every_m`` metres
    travelled) against the truth; ``poses``: the run's (default: a log's own, KISS-ICP's for
    scans); ``reference_poses`` (with ``calib``: their scanner -> pose-frame transform) add
    APE and RPE. ``Tracked.rows`` are the rows of ``track.csv``."""
    options = RunOptions(poses=_path(poses), reference_poses=_path(reference_poses),
                         calib=_path(calib), every=every if every_m is None else None,
                         every_m=every_m)
    return track_plan(plan_run(Path(run_path), options), Path(truth_path),
                      settings or Settings())


def _path(path: str | Path | None) -> Path | None:
    return None if path is None else Path(path)
