"""Score a run's map as it grows: one evaluation per step against a truth prepared once.

Each step scores the map of the scans so far inside its footprint (the partial-map rules), with
the settings of ``pcmapq eval``. The first step searches for the map's pose in the truth (or
starts from ``--init``); every later one starts ICP from the pose the step before found (a 3D
run against a 3D truth: its 3D registration, so that every step is registered in 3D and has
the 3D figures), and searches again only when that pose no longer fits (a confidence below the
minimum). A step the method cannot score (too few walls yet, a place it does not recognise) is
kept, with no figures and the reason.

Besides the figures of ``pcmapq eval`` a step holds ``slide_m``: how far the alignment moved
the positions of the first scored step's scans since that step, RMS metres (a map that drifts
may drag the alignment of the whole map along, and its first part slide away from where it
fitted); and ``local_offset_m``: how far the readings of the scans since the step before lie
off the truth where the map's alignment puts them, RMS metres (they alone are aligned to the
truth, ICP from the map's pose, and moved that much): the part of the map the robot has just
made, off the truth by drift even while the alignment of the whole map holds still.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field, replace

import numpy as np

from pcmapq.align import align
from pcmapq.core.errors import EvaluationError, InputError, SettingsRefused
from pcmapq.core.frames import Frames
from pcmapq.core.transform import Similarity2D
from pcmapq.core.voxels import evenly, voxel_centroids
from pcmapq.evaluation.pipeline import (
    Underway,
    evaluate_prepared,
    finish_evaluation,
    start_evaluation,
)
from pcmapq.evaluation.placing import Placed
from pcmapq.evaluation.truth import PreparedTruth
from pcmapq.io import PointMap
from pcmapq.metrics.trajectory import ape, rpe
from pcmapq.results.result import Result
from pcmapq.results.rows import step_columns, table_row
from pcmapq.settings import Settings
from pcmapq.track.runs import Run
from pcmapq.track.steps import travelled

#: The summary columns a step does not repeat (they name the inputs or a batch's outcome).
NOT_PER_STEP = ("name", "map", "truth", "gates", "exit_code", "error")
#: Positions of the first scored step that measure the slide (an even sample of them).
SLIDE_POINTS = 2000
#: The newest readings are aligned through this many of their voxel centroids at most (evenly
#: spread): a pose is as sure from a few thousand wall points, and a 3D run's scans hold many.
LOCAL_POINTS = 5000
#: Threads finding the features of placed steps while the next step is placed.
FEATURE_THREADS = 2
#: The steps' full results are kept while their map rasters and footprints take at most this
#: many bytes in all (the truth's raster is shared); beyond it none is.
KEEP_BYTES = 512 * 2**20
#: Where a step's ICP starts: a plan pose (``--init``'s), or the 16 numbers of a rigid 4x4
#: map -> truth transform, row by row (``--init-3d``'s: two 3D clouds registered in 3D).
Start = Similarity2D | tuple[float, ...]


@dataclass(frozen=True)
class PoseOptions:
    """How the trajectory errors compare the estimate with the reference, as evo's options:
    ``align`` (-a, SE(3) Umeyama), ``correct_scale`` (-s), RPE's ``delta`` in frames."""

    align: bool = False
    correct_scale: bool = False
    delta: int = 1


@dataclass(frozen=True)
class Step:
    """One step: the map of the first ``scans`` scans; ``time_s`` at its last scan, seconds
    from a recording's start or from a log's first scan (None without timestamps), and
    ``distance_m`` travelled by then; ``figures`` the flat columns of
    :func:`~pcmapq.results.rows.table_row` plus ``slide_m``, ``local_offset_m`` and the
    trajectory errors (None when undefined); ``note`` why a step was not scored ("" when it
    was);
    ``start`` the pose its ICP started from (:data:`Start`; None: the global search);
    ``frames`` the frames its result put the map and truth in (None when not scored);
    ``result`` its full result, while the steps' rasters fit in :data:`KEEP_BYTES` (None
    otherwise: :func:`result_at` scores it again)."""

    step: int
    scans: int
    time_s: float | None
    distance_m: float
    figures: dict[str, float | None]
    note: str = ""
    start: Start | None = None
    frames: Frames | None = field(default=None, compare=False, repr=False)
    result: Result | None = field(default=None, compare=False, repr=False)

    @property
    def scored(self) -> bool:
        return not self.note


def plane_points(xyz: np.ndarray, frames: Frames) -> np.ndarray:
    """Map-frame points (N, 3) in the truth's plan, (N, 2) metres: levelled, then aligned."""
    if frames.map_levelling is not None:
        xyz = xyz @ frames.map_levelling.rotation.T
    return frames.map_to_truth().apply(xyz[:, :2])


def pose_errors(estimate: np.ndarray, reference: np.ndarray,
                options: PoseOptions) -> dict[str, float | None]:
    """APE (translation, metres) and RPE (translation, metres; rotation, degrees) RMSE of
    the estimate (K, 4, 4) against the reference, as evo_ape and evo_rpe compute them."""
    kw = {"align": options.align, "correct_scale": options.correct_scale}
    if len(estimate) < 3 and options.align:
        kw = {"align": False, "correct_scale": False}  # Umeyama needs three poses
    return {"ape_rmse_m": ape(estimate, reference, **kw).stats.rmse,
            "ape_max_m": ape(estimate, reference, **kw).stats.max,
            "rpe_rmse_m": rpe(estimate, reference, options.delta, **kw).stats.rmse,
            "rpe_rot_rmse_deg": rpe(estimate, reference, options.delta,
                                    relation="rotation_angle_deg", **kw).stats.rmse}


def figures_of(result: Result) -> dict[str, float | None]:
    """A result's flat figures: :func:`~pcmapq.results.rows.table_row` without the inputs and
    outcome, then :func:`~pcmapq.results.rows.step_columns` (the detectors' mean precision,
    the wall precision at each tau)."""
    doc = result.to_dict(features=False)
    row = table_row("", doc)
    figures = {k: v for k, v in row.items() if k not in NOT_PER_STEP}
    return {**figures, **step_columns(doc, {name: d.matching.precision
                                            for name, d in result.detectors.items()})}


def place_step(source, prepared: PreparedTruth, settings: Settings,
               start: Start | None) -> tuple[Underway, Start | None]:
    """One step's map checked, aligned and drawn, the first half of its evaluation
    (:func:`~pcmapq.evaluation.pipeline.start_evaluation`), ICP from ``start`` (None: the
    global search); a start whose pose is refused is followed by a global search. The
    evaluation underway and the start it used; EvaluationError for a map of no point yet
    (scans with no return within their range limits), SettingsRefused for settings no step's
    map can follow."""
    if isinstance(source, PointMap) and not len(source.points):
        raise EvaluationError(f"{source.path}: the scans so far hold no point (no return "
                              "within their range limits)")
    option = settings.alignment
    if start is None or not option.enabled:
        return start_evaluation(source, prepared, settings), option.init_3d or option.init
    try:
        return start_evaluation(source, prepared, settings_from(settings, start)), start
    except EvaluationError:
        if option.force:
            raise
        return start_evaluation(source, prepared, settings), None


def settings_from(settings: Settings, start: Start | None) -> Settings:
    """The settings a step was scored with: ICP from ``start`` (None: as given), a plan pose
    as ``--init`` gives it, a 3D one as ``--init-3d`` does."""
    if start is None or not settings.alignment.enabled:
        return settings
    if isinstance(start, Similarity2D):
        return replace(settings, alignment=replace(settings.alignment, init=start, init_3d=None))
    return replace(settings, alignment=replace(settings.alignment, init=None, init_3d=start))


def next_start(placed: Placed) -> Start:
    """Where the next step's ICP starts: the pose this step's map was placed at, its 3D
    registration when it had one (so that every step of two 3D clouds is registered in 3D),
    else its plan's alignment."""
    if placed.registration is not None:
        return tuple(float(v) for v in np.asarray(placed.registration.transform).ravel())
    return placed.alignment.transform


def track(run: Run, prepared: PreparedTruth, settings: Settings, ends: np.ndarray,
          reference: np.ndarray | None = None, pose_options: PoseOptions = PoseOptions(),
          tick: Callable[[int], None] = lambda done: None) -> list[Step]:
    """Score the map of ``run`` after each of ``ends`` scans against ``prepared``.

    reference: (K, 4, 4) reference poses, one per scan, for the trajectory errors of each
    step. tick: ``tick(scans done)``.

    Two stages overlap: this thread aligns and draws each step's map in turn (a step's ICP
    starts from the pose the step before found), while up to :data:`FEATURE_THREADS` others
    (fewer when the memory allows fewer maps at once: ``prepared.maps``) find the features of
    the steps already placed, score them and align their newest readings alone
    (:func:`local_offset`). Each step's result depends on its map and its
    start alone, so the steps are the same as one after the other."""
    distance = travelled(run.poses)
    stamps = run.stamps
    steps: list[Step | None] = [None] * len(ends)
    pending: list[tuple[int, Future]] = []
    start = settings.alignment.init

    held: int | None = 0  # bytes of the results kept; None once they no longer fit

    def collect(wait_for: int) -> None:
        """Score the placed steps while more than ``wait_for`` are in flight; keep their
        results while they fit in :data:`KEEP_BYTES`."""
        nonlocal held
        while len(pending) > wait_for:
            index, job = pending.pop(0)
            step = job.result()
            if step.result is not None and held is not None:
                held += step.result.map_occupied.nbytes + step.result.overlap.footprint.nbytes
                if held > KEEP_BYTES:
                    held = None
                    steps[:] = [s if s is None else replace(s, result=None) for s in steps]
            steps[index] = step if held is not None else replace(step, result=None)

    scoring = min(FEATURE_THREADS, prepared.maps - 1)  # steps scored while one is placed
    with ThreadPoolExecutor(max(scoring, 1)) as scorers:
        for index, (end, (source, recent)) in enumerate(zip(ends, run.steps(ends, tick),
                                                            strict=True)):
            end = int(end)
            time_s = None if stamps is None else float(stamps[end - 1] - run.time_origin)
            extra = {} if reference is None else pose_errors(run.poses[:end], reference[:end],
                                                             pose_options)
            at = (index, end, time_s, float(distance[end - 1]))
            try:
                underway, used = place_step(source, prepared, settings, start)
            except SettingsRefused:
                raise  # no step's map can follow them: the run is refused, as eval's map is
            except (EvaluationError, InputError) as err:
                steps[index] = Step(*at, {"slide_m": None, "local_offset_m": None, **extra},
                                    str(err), start)
                continue
            if settings.alignment.enabled:
                start = next_start(underway.placed)
            pending.append((index, scorers.submit(_finish, at, recent, underway, used, extra)))
            collect(scoring)
        collect(0)
    return _with_slide([s for s in steps if s is not None], run.poses)


def local_offset(recent: np.ndarray, side: Placed, prepared: PreparedTruth,
                 settings: Settings) -> float | None:
    """How far the readings ``recent`` (N, 3, map frame, metres) lie off the truth where the
    placed map ``side`` puts them: aligned alone to the truth (ICP from the map's pose, rigid,
    through at most :data:`LOCAL_POINTS` of their voxel centroids), their RMS displacement,
    metres. A 3D map's readings are levelled and cut to its wall band as the map is. None for
    fewer than 3 readings or with the scale estimated."""
    level, transform = side.level, side.alignment.transform
    if level is not None:
        levelled = np.asarray(recent) @ np.asarray(level.rotation).T
        height = levelled[:, 2] - level.floor_z_m
        recent = levelled[(height >= settings.raster.band_low)
                          & (height <= settings.raster.band_high)]
    xy = np.asarray(recent, dtype=np.float64)[:, :2]
    if len(xy) < 3 or settings.alignment.scale:
        return None
    params = settings.alignment.params
    fitted = align(evenly(voxel_centroids(xy, params.voxel), LOCAL_POINTS), prepared.xy,
                   params, init=transform, target=prepared.aligner).transform
    moved = fitted.apply(xy) - transform.apply(xy)
    return float(np.sqrt(np.mean(np.sum(moved**2, axis=1))))


def _finish(at: tuple, recent: np.ndarray, underway: Underway, used: Start | None,
            extra: dict) -> Step:
    """A placed step's evaluation finished (its features matched and scored,
    :func:`~pcmapq.evaluation.pipeline.finish_evaluation`), and the offset of its ``recent``
    readings (:func:`local_offset`): its :class:`Step` (``slide_m`` unset)."""
    extra = {"local_offset_m": local_offset(recent, underway.placed, underway.prepared,
                                            underway.settings), **extra}
    try:
        result = finish_evaluation(underway)
    except (EvaluationError, InputError) as err:
        return Step(*at, {"slide_m": None, **extra}, str(err), used)
    return Step(*at, {**figures_of(result), "slide_m": None, **extra}, "", used,
                result.frames, result)


def _with_slide(steps: list[Step], poses: np.ndarray) -> list[Step]:
    """The steps with ``slide_m``: how far each scored step's alignment moves the positions
    of the first scored step's scans from where that step put them, RMS metres."""
    first = next((s for s in steps if s.scored), None)
    if first is None:
        return steps
    positions = poses[:first.scans, :3, 3]
    sample = positions[np.linspace(0, first.scans - 1,
                                   min(first.scans, SLIDE_POINTS)).astype(int)]
    origin = plane_points(sample, first.frames)
    out = []
    for s in steps:
        if s.scored:
            moved = plane_points(sample, s.frames) - origin
            s = replace(s, figures={**s.figures,
                                    "slide_m": float(np.sqrt(np.mean(np.sum(moved**2, axis=1))))})
        out.append(s)
    return out


def result_at(run: Run, prepared: PreparedTruth, settings: Settings, step: Step) -> Result:
    """The full result of a scored step: the one :func:`track` kept, else computed again as
    it computed it (the same map, the same start: the same result)."""
    if step.result is not None:
        return step.result
    return evaluate_prepared(next(run.maps([step.scans])), prepared,
                             settings_from(settings, step.start))
