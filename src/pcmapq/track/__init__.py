"""Quality over time (``pcmapq track``): a SLAM run's map scored as it grows.

:func:`track_run` scores the map of the scans so far every N scans (or D metres) against a
truth prepared once, :func:`track_recording` every map a recording published, and
:func:`write_track` writes ``track.csv``, ``track.json``, ``track.png`` and ``track.html`` (the
curves, and the vectorial map at the worst drop with the robot's path). Each step's map is
scored by :func:`pcmapq.evaluation.pipeline.evaluate_prepared`, as ``pcmapq eval`` scores one.
Modules: :mod:`~pcmapq.track.plan` (a run opened and its steps set, then scored: the command
line and the API), :mod:`~pcmapq.track.tracked` (a run tracked: its steps, worst drop and
step shown), :mod:`~pcmapq.track.runs` (the scans and poses of a run, and its growing map),
:mod:`~pcmapq.track.recording` (a recording's published maps), :mod:`~pcmapq.track.steps`
(when to score), :mod:`~pcmapq.track.timeline` (the scoring loop), :mod:`~pcmapq.track.drop`
(the worst drop), :mod:`~pcmapq.track.outputs` (the files)."""

from __future__ import annotations

from pcmapq.track.drop import worst_drop
from pcmapq.track.outputs import FILES, write_track
from pcmapq.track.plan import Plan, RunOptions, plan_run, track_plan
from pcmapq.track.recording import Recording
from pcmapq.track.runs import open_run, planar_of, planar_poses
from pcmapq.track.steps import step_ends, travelled
from pcmapq.track.timeline import PoseOptions, Step, track
from pcmapq.track.tracked import Tracked, track_recording, track_run

__all__ = ["FILES", "Plan", "PoseOptions", "Recording", "RunOptions", "Step", "Tracked",
           "open_run", "planar_of", "planar_poses", "plan_run", "step_ends", "track",
           "track_plan", "track_recording", "track_run", "travelled", "worst_drop",
           "write_track"]
