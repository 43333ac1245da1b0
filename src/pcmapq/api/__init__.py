"""pcmapq as a library: the four things the commands do, each one call, in metres.

    import pcmapq
    result = pcmapq.evaluate("map.pgm", "truth.png", pcmapq.Settings())
    result.to_json()

:func:`evaluate` is ``pcmapq eval``, :func:`inspect` ``pcmapq inspect``,
:func:`track_quality` ``pcmapq track`` (without its files; ``pcmapq.track`` is the package that
does the work), :func:`load_map` the loader every command uses, :func:`read_settings` what
``--config FILE`` reads.
Frames: ``p_truth = s * R(yaw) * p_map + t``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pcmapq.evaluation.inspect_map import inspect_map
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import OccupancyMap, PointMap, load_map
from pcmapq.results.result import Result
from pcmapq.settings import TRACK_EVERY, NoRefConfig, Settings
from pcmapq.settings.file import read_settings
from pcmapq.track import Tracked, open_run, step_ends, track_run, travelled
from pcmapq.track.runs import reference_poses_of

__all__ = ["NoRefConfig", "Result", "Settings", "Tracked", "evaluate", "inspect", "load_map",
           "read_settings", "track_quality"]


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
    run = open_run(Path(run_path), None if poses is None else Path(poses))
    reference = (None if reference_poses is None else
                 reference_poses_of(Path(reference_poses), len(run),
                                    None if calib is None else Path(calib)))
    ends = step_ends(len(run), every if every_m is None else None, every_m,
                     travelled(run.poses))
    return track_run(run, Path(truth_path), settings or Settings(), ends, reference=reference,
                     reference_path=None if reference_poses is None else Path(reference_poses))
