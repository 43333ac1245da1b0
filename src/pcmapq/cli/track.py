"""``pcmapq track``: a run's map scored as it grows."""

from __future__ import annotations

import sys
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console

from pcmapq.cli import options, terminal
from pcmapq.cli.commands import HELP, MaxMemory, ScanTopic, TfFrame, app, memory_limit
from pcmapq.cli.terminal import (
    report_errors,
    scan_bar,
    step_progress,
)
from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.io import targets
from pcmapq.io.formats import scan_formats
from pcmapq.io.writers import OutputSet, write_atomic
from pcmapq.settings import TRACK_EVERY

if TYPE_CHECKING:  # imported when the command runs: the command line starts without it
    from pcmapq.track import RunOptions


@app.command("track", help=HELP["track"])
@options.settings_options("track")
def track_command(
    ctx: typer.Context,
    paths: Annotated[list[Path], typer.Argument(
        metavar="RUN TRUTH", help="The run: a CARMEN log (.log/.log.gz), scans (a folder of "
        f"{scan_formats()} scans, a ROS bag, an MCAP file), or a ROS recording of the maps a "
        "SLAM system published (nav_msgs/OccupancyGrid, scored on the recording's time "
        "axis); then the ground truth, as eval's.")],
    out: Annotated[Path, typer.Option(
        help="Folder of the results: track.csv, track.json, track.png, track.html.")],
    poses: Annotated[Path | None, typer.Option(
        help="The run's estimated poses, one per scan (KITTI or TUM file); default: a log's "
        "own, KISS-ICP's for scans.")] = None,
    reference_poses: Annotated[Path | None, typer.Option(
        help="Reference poses, one per scan (KITTI or TUM file, or a CARMEN log's): adds the "
        "trajectory's APE and RPE at every step, as evo computes them.")] = None,
    calib: Annotated[Path | None, typer.Option(
        help="As map's: the scanner -> pose-frame transform T of the reference poses (12 or "
        "16 numbers, or a KITTI calib.txt with Tr:; KITTI's poses are the left camera's): "
        "they are moved into the scanner's frame, inv(T) P_k T, the frame of the run's "
        "poses.")] = None,
    every: Annotated[int | None, typer.Option(
        help=f"Score the map every N scans (default {TRACK_EVERY}).", min=1,
        show_default=False)] = None,
    every_m: Annotated[float | None, typer.Option(
        help="Score the map every D metres travelled instead.", min=1e-6,
        callback=options.finite)] = None,
    scan_topic: ScanTopic = None,
    pose_topic: Annotated[str | None, typer.Option(
        help="A recording's nav_msgs/Odometry or geometry_msgs/PoseStamped topic: the run's "
        "poses, interpolated at each scan's time (instead of KISS-ICP's).")] = None,
    frame: TfFrame = None,
    map_topic: Annotated[str | None, typer.Option(
        help="A recording's OccupancyGrid topic to score (default: the only one, or /map).")
    ] = None,
    every_s: Annotated[float | None, typer.Option(
        help="A recording's maps: score at most one every S seconds (and the last); default "
        "every map published that differs from the one before.", min=1e-6,
        callback=options.finite)] = None,
    step: Annotated[int | None, typer.Option(
        help="The step the report shows (default: where the worst drop starts, else the "
        "last).", min=0,
        show_default=False)] = None,
    align_poses: Annotated[bool, typer.Option(
        "--align-poses", help="APE/RPE: align the poses first (SE(3) Umeyama, evo's -a).")
    ] = False,
    correct_scale: Annotated[bool, typer.Option(
        "--correct-scale", help="APE/RPE: correct the scale too (evo's -s).")] = False,
    delta: Annotated[int, typer.Option(help="RPE: pairs this many scans apart.", min=1)] = 1,
    max_memory: MaxMemory = None,
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Also write track.json to this path ('-' for stdout only).")] = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,

    **settings_values: Any,
) -> None:
    from pcmapq.report.timeline import drop_words
    from pcmapq.track import PoseOptions, RunOptions, plan_run, track_plan, write_track

    if len(paths) != 2:
        raise typer.BadParameter("give RUN and TRUTH", param_hint="RUN TRUTH")
    run_path, truth_path = paths
    err = Console(stderr=True)
    json_path = targets.kept(json_path)
    shown = not quiet and json_path != "-"
    with report_errors(err), terminal.show_warnings(err), \
            step_progress(err, enabled=shown) as progress:
        settings = options.settings_of(ctx, "track", settings_values)
        if every is not None and every_m is not None:
            raise typer.BadParameter("give one of --every and --every-m", param_hint="--every")
        if out.exists() and not out.is_dir():
            raise InputError(f"{out}: --out: not a folder")
        targets.check_outputs({"--json": json_path}, None,
                              inputs=(*paths, poses, reference_poses, calib,
                                      settings_values.get("config")))
        limit = memory_limit(max_memory)
        run_options = RunOptions(
            poses=poses, reference_poses=reference_poses, calib=calib, every=every,
            every_m=every_m, scan_topic=scan_topic, pose_topic=pose_topic, frame=frame,
            pose_options=PoseOptions(align_poses, correct_scale, delta), map_topic=map_topic,
            every_s=every_s)
        _check_options(run_options, run_path)
        with scan_bar(err, enabled=shown) as tick:
            plan = plan_run(run_path, run_options, progress=tick)
        if plan.ends is not None:
            _check_step(step, len(plan.ends), "run")
        tracked = track_plan(plan, truth_path, settings, show=step, progress=progress,
                             memory_limit=limit)
        if plan.ends is None:
            _check_step(step, len(tracked.steps), "recording")
        wrote = write_track(tracked, out, options.command_line(ctx))
        if json_path not in (None, "-"):
            with OutputSet() as outputs:
                write_atomic(Path(json_path), wrote[1].read_text(), outputs)
                outputs.commit()
    scored = sum(s.scored for s in tracked.steps)
    total = (f"{count(tracked.steps[-1].scans, 'map')} published" if plan.ends is None
             else count(len(tracked.run), "scan"))
    if json_path == "-":
        sys.stdout.write(wrote[1].read_text())
    elif not quiet:
        drop = None if tracked.drop is None else asdict(tracked.drop)
        err.print(f"{count(len(tracked.steps), 'step')} ({scored} scored) of {total}; "
                  f"{drop_words(tracked.rows, drop)}; wrote {out}/track.csv, "
                  "track.json, track.png, track.html", markup=False, highlight=False,
                  soft_wrap=True)
    if not scored:  # nothing to measure: said as such, and not a success
        err.print(f"pcmapq: error: {run_path}: no step could be scored; the last: "
                  f"{tracked.steps[-1].note}", markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(1)


def _check_options(given: RunOptions, run_path: Path) -> None:
    """Refuse, before any work, options of a recording's published maps with those of a run's
    scans or on a run that has none, --calib without a KITTI or TUM --reference-poses, and
    --poses with --pose-topic."""
    from pcmapq.io.bags import has_grids
    from pcmapq.io.carmen import is_carmen

    scan_options = [o for o, v in (
        ("--poses", given.poses), ("--reference-poses", given.reference_poses),
        ("--calib", given.calib), ("--every", given.every), ("--every-m", given.every_m),
        ("--scan-topic", given.scan_topic), ("--pose-topic", given.pose_topic),
        ("--frame", given.frame)) if v is not None]
    map_options = [o for o, v in (("--map-topic", given.map_topic),
                                  ("--every-s", given.every_s)) if v is not None]
    if scan_options and map_options:
        raise InputError(f"{run_path}: {', '.join(map_options)} score a recording's "
                         f"published maps, {', '.join(scan_options)} a run's scans: give "
                         "the options of one")
    if map_options and not has_grids(run_path, given.map_topic):
        raise InputError(f"{run_path}: {', '.join(map_options)} apply to a ROS "
                         "recording of published maps (nav_msgs/OccupancyGrid)")
    if given.calib is not None and (given.reference_poses is None
                                    or is_carmen(given.reference_poses)):
        raise InputError(f"{given.calib}: --calib moves the poses of a --reference-poses KITTI "
                         "or TUM file into the scanner's frame; none is given")
    if given.poses is not None and given.pose_topic is not None:
        raise InputError("--poses and --pose-topic: give one of the two")


def _check_step(step: int | None, steps: int, what: str) -> None:
    """Refuse a --step the run does not have."""
    if step is not None and step >= steps:
        raise typer.BadParameter(f"{step}: the {what} has {count(steps, 'step')}, 0 to "
                                 f"{steps - 1}",
                                 param_hint="--step")
