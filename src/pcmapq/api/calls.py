"""The library's calls for the commands that have no one function in the pipeline:
:func:`inspect` (``pcmapq inspect``) and :func:`track_quality` (``pcmapq track``, without its
files). Lengths in metres; frames: ``p_truth = s * R(yaw) * p_map + t``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pcmapq.evaluation.inspect_map import inspect_map
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.settings import NoRefConfig, Settings
from pcmapq.track import Tracked, open_run, step_ends, track_run, travelled
from pcmapq.track.runs import reference_poses_of

__all__ = ["inspect", "track_quality"]


def inspect(map_path: str | Path, config: NoRefConfig | None = None,
            resolution: float | None = None) -> dict[str, Any]:
    """``pcmapq inspect``: the no-reference figures of one map (a cloud, image or CARMEN log;
    ``resolution``: metres per pixel of an image without YAML), as its JSON holds them."""
    source: OccupancyMap | PointMap = load_map(Path(map_path), resolution)
    return inspect_map(source, config or NoRefConfig())


def track_quality(run_path: str | Path, truth_path: str | Path, settings: Settings | None = None, *,
          every: int | None = 20, every_m: float | None = None,
          poses: str | Path | None = None, reference_poses: str | Path | None = None,
          calib: str | Path | None = None) -> Tracked:
    """``pcmapq track``: the run's map scored every ``every`` scans (or ``every_m`` metres
    travelled) against the truth; ``poses``: the run's (default: a log's own, KISS-ICP's for
    scans); ``reference_poses`` (with ``calib``: their scanner -> pose-frame transform) add
    APE and RPE. ``Tracked.rows`` are the rows of ``track.csv``."""
    run = open_run(Path(run_path), None if poses is None else Path(poses))
    reference = (None if reference_poses is None else
                 reference_poses_of(Path(reference_poses), len(run),
                                    None if calib is None else Path(calib)))
    ends = step_ends(len(run), every if every_m is None else None, every_m,
                     travelled(run.poses))
    return track_run(run, Path(truth_path), settings or Settings(), ends, reference=reference,
                     reference_path=None if reference_poses is None else Path(reference_poses))
