"""``pcmapq track`` without its files, as the command line and :func:`pcmapq.track_quality`
run it: :func:`plan_run` opens the run (a recording's published maps, or a run's scans with
their poses, KISS-ICP's when none are given) and sets its steps; :func:`track_plan` scores
them against the truth. The two are apart so that a caller can check the steps asked for
(``--step``) before any is scored."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from pcmapq.core.words import count
from pcmapq.io.bags import has_grids
from pcmapq.settings import TRACK_EVERY, Settings
from pcmapq.track.recording import Recording
from pcmapq.track.runs import Run, open_run, reference_poses_of
from pcmapq.track.steps import step_ends, travelled
from pcmapq.track.timeline import PoseOptions
from pcmapq.track.tracked import Tracked, track_recording, track_run


@dataclass(frozen=True)
class RunOptions:
    """How a run is read and when it is scored (None: the default). A run's scans: its
    ``poses`` (a KITTI or TUM file; default a log's own, KISS-ICP's for scans), a recording's
    ``scan_topic``, ``pose_topic`` and ``frame``, ``reference_poses`` (with ``calib``, their
    scanner -> pose-frame transform) and how they compare (``pose_options``), a step every
    ``every`` scans (default :data:`~pcmapq.settings.TRACK_EVERY`) or ``every_m`` metres
    travelled. A recording's published maps: their ``map_topic``, at most one every
    ``every_s`` seconds."""

    poses: Path | None = None
    reference_poses: Path | None = None
    calib: Path | None = None
    every: int | None = None
    every_m: float | None = None
    scan_topic: str | None = None
    pose_topic: str | None = None
    frame: str | None = None
    pose_options: PoseOptions = PoseOptions()
    map_topic: str | None = None
    every_s: float | None = None

    def of_scans(self) -> bool:
        """Whether an option of a run's scans is given (a recording's scans are then
        tracked, not its published maps)."""
        return any(v is not None for v in (self.poses, self.reference_poses, self.calib,
                                           self.every, self.every_m, self.scan_topic,
                                           self.pose_topic, self.frame))


@dataclass(frozen=True)
class Plan:
    """A run ready to score: a run's scans with the scan counts of its steps (``ends``) and
    its reference poses (K, 4, 4; None without), or a recording's published maps
    (``ends`` None: its steps are known once read); ``every``: the step rule as
    ``track.json`` names it."""

    run: Run | Recording
    ends: np.ndarray | None
    reference: np.ndarray | None
    options: RunOptions
    every: dict


def plan_run(run_path: Path, options: RunOptions = RunOptions(),  # noqa: B008 (frozen)
             progress: Callable[[int, int], None] | None = None) -> Plan:
    """The run at ``run_path`` opened: a recording holding OccupancyGrid messages when no
    option of scans is given, else its scans and their poses (``progress(done, total)``
    while KISS-ICP finds them), the reference poses read and the steps set. InputError (one
    line) for a run, pose file or reference pose file that cannot be read or does not
    match."""
    if not options.of_scans() and has_grids(run_path, options.map_topic):
        return Plan(Recording(run_path, options.map_topic, options.every_s), None, None,
                    options, {"every_s": options.every_s, "map_topic": options.map_topic})
    run = open_run(run_path, options.poses, progress=progress, scan_topic=options.scan_topic,
                   pose_topic=options.pose_topic, frame=options.frame)
    reference = (None if options.reference_poses is None
                 else reference_poses_of(options.reference_poses, len(run), options.calib))
    every = (options.every or TRACK_EVERY) if options.every_m is None else None
    ends = step_ends(len(run), every, options.every_m, travelled(run.poses))
    return Plan(run, ends, reference, options, {"every_scans": every,
                                                "every_m": options.every_m})


def track_plan(plan: Plan, truth_path: Path, settings: Settings, *, show: int | None = None,
               progress: Callable[[str], None] = lambda s: None,
               memory_limit: int | None = None) -> Tracked:
    """The planned run scored against the truth at ``truth_path``
    (:func:`~pcmapq.track.tracked.track_run`, or
    :func:`~pcmapq.track.tracked.track_recording` for published maps); ``show``: the step the
    report shows; ``progress``: each stage, and the scans scored so far, in words."""
    run = plan.run
    if isinstance(run, Recording):
        tracked = track_recording(run, truth_path, settings, show=show, progress=progress,
                                  memory_limit=memory_limit)
    else:
        options = plan.options
        tracked = track_run(run, truth_path, settings, plan.ends, reference=plan.reference,
                            pose_options=options.pose_options,
                            reference_path=options.reference_poses, show=show,
                            progress=progress,
                            tick=lambda done: progress(f"scoring: {done} of "
                                                       f"{count(len(run), 'scan')}"),
                            memory_limit=memory_limit)
    return replace(tracked, every=plan.every)
