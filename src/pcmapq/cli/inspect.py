"""``pcmapq inspect``: no-reference figures of one map. The figures, the loaders and the
LiDAR front end are imported when the command runs, not when its help is shown."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import numpy as np
import typer
from rich.console import Console

from pcmapq.cli import options, terminal
from pcmapq.cli.commands import HELP, MaxMemory, app, memory_limit
from pcmapq.cli.terminal import (
    report_errors,
)
from pcmapq.core import memory
from pcmapq.core.bounds import Box
from pcmapq.io import load_map, targets
from pcmapq.io.formats import map_formats, scan_formats
from pcmapq.io.writers import OutputSet, write_atomic

if TYPE_CHECKING:
    from pcmapq.io import OccupancyMap, PointMap

#: The crop option of inspect, named in messages.
CROP = "--map-crop"


def checked(source: OccupancyMap | PointMap, box: Box | None,
            limit: int | None) -> OccupancyMap | PointMap:
    """The map cut to ``box``, after the checks eval makes on its inputs: no wider than it
    can score (:func:`~pcmapq.io.extent.check_span`) and, for an image, within the memory
    limit its walls' image takes, each refused in one line that says what looks wrong."""
    from pcmapq.evaluation.truth import needed_memory
    from pcmapq.io.extent import check_span, hint
    from pcmapq.io.extent import crop as crop_input
    from pcmapq.io.occupancy import OccupancyMap

    source = source if box is None else crop_input(source, box, CROP)
    check_span(source, CROP)
    if isinstance(source, OccupancyMap):
        memory.guard(needed_memory((source,), source.grid), limit, str(source.path),
                     lambda: hint(source, CROP))
    return source


@app.command("inspect", help=HELP["inspect"])
@options.settings_options("inspect")
def inspect_command(
    ctx: typer.Context,
    map_path: Annotated[Path | None, typer.Argument(
        metavar="[MAP]", help=f"Map to inspect: {map_formats()}. Or --scans with --poses.",
        show_default=False)] = None,
    scans: Annotated[Path | None, typer.Option(
        help=f"Inspect these scans placed at --poses instead: a folder of {scan_formats()} "
        "scans, or a ROS recording (.bag, .db3, .mcap, a ROS 2 bag folder).")] = None,
    poses: Annotated[Path | None, typer.Option(
        help="With --scans: one pose per scan, a KITTI or TUM file or a folder of 4x4 text "
        "files (name order); the map is in the first scan's frame.")] = None,
    orth_subset: Annotated[Path | None, typer.Option(
        help="MOM's orthogonal planes (a map-metrics .npy or .npz) in the map's frame, or in "
        "the frame of the scan at --orth-pose; otherwise pcmapq extracts them.")] = None,
    orth_pose: Annotated[Path | None, typer.Option(
        help="With --orth-subset: the 4x4 pose of the scan whose frame the planes are in "
        "(with --poses, placed relative to the first pose, as the map).")] = None,
    max_memory: MaxMemory = None,
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Write the figures as JSON to this path ('-' for stdout only).")] = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,

    **settings_values: Any,
) -> None:
    from pcmapq.evaluation.inspect_map import inspect_map, summary_lines, to_json
    from pcmapq.io.clouds import PointMap
    from pcmapq.mapping import posed_map, read_pose_matrix, read_poses
    from pcmapq.metrics.posed import place_subset, read_orthogonal_subset

    err = Console(stderr=True)
    json_path = targets.kept(json_path)
    with report_errors(err), terminal.show_warnings(err):
        settings = options.settings_of(ctx, "inspect", settings_values)
        if settings_values.get("map_resolution") == "auto":
            raise typer.BadParameter("'auto' estimates a map's scale against a truth, which "
                                     "inspect has none of: give metres per pixel",
                                     param_hint="--map-resolution")
        if (map_path is None) == (scans is None) or (scans is None) != (poses is None):
            raise typer.BadParameter("give MAP, or --scans DIR with --poses FILE",
                                     param_hint="MAP")
        if orth_pose is not None and orth_subset is None:
            raise typer.BadParameter("--orth-pose places --orth-subset: give both",
                                     param_hint="--orth-pose")
        targets.check_outputs({"--json": json_path}, None,
                              inputs=(map_path, scans, poses, orth_subset, orth_pose,
                                      settings_values.get("config")))
        first = np.eye(4)
        if scans is not None and poses is not None:
            trajectory = read_poses(poses)
            first = trajectory[0]
            placed = posed_map(scans, trajectory)
            source = PointMap.of_scans(scans, placed)
        else:
            source = load_map(map_path, settings.map.resolution,
                              memory_limit=memory_limit(max_memory), topic=settings.map.topic,
                              topic_option="--map-topic")
        source = checked(source, settings.map.crop, memory_limit(max_memory))
        planes = None if orth_subset is None else read_orthogonal_subset(orth_subset)
        if planes is not None and orth_pose is not None:
            planes = place_subset(planes, read_pose_matrix(orth_pose), first)
        record = inspect_map(source, settings.noref, planes, options.command_line(ctx))
        if json_path not in (None, "-"):
            with OutputSet() as outputs:
                write_atomic(Path(json_path), to_json(record), outputs)
                outputs.commit()
    if json_path == "-":
        sys.stdout.write(to_json(record))
    elif not quiet:
        for line in summary_lines(record):
            print(line)
        if json_path is not None:
            err.print(f"wrote {json_path}", markup=False, highlight=False, soft_wrap=True)


