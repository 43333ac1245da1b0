"""``pcmapq map``: a map from LiDAR scans (KISS-ICP or given poses). The LiDAR front end is
imported when the command runs, not when its help is shown."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from pcmapq.cli import options, terminal
from pcmapq.cli.commands import HELP, ScanTopic, TfFrame, app
from pcmapq.cli.terminal import (
    report_errors,
    scan_bar,
)
from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.io import targets
from pcmapq.io.formats import scan_formats
from pcmapq.io.writers import OutputSet, write_cloud


@app.command("map", help=HELP["map"])
def map_command(
    source: Annotated[Path, typer.Argument(
        help=f"Scan sequence: a folder of {scan_formats()} scans (KITTI's .bin), or a ROS "
        "recording (.bag, .db3, .mcap, a ROS 2 bag folder) of PointCloud2 or LaserScan "
        "messages.")],
    out: Annotated[Path, typer.Option(help="The map, .ply or .pcd (voxel centroids).")],
    poses_out: Annotated[Path | None, typer.Option(
        help="Write the scan poses in KITTI format (12 numbers a line), as evo reads them.")
    ] = None,
    tum_out: Annotated[Path | None, typer.Option(
        help="Write the scan poses in TUM format (t x y z qx qy qz qw; t = scan index).")
    ] = None,
    poses: Annotated[Path | None, typer.Option(
        help="Build the map from these poses (KITTI or TUM file) instead of running KISS-ICP.")
    ] = None,
    scan_topic: ScanTopic = None,
    pose_topic: Annotated[str | None, typer.Option(
        help="Build the map from a recording's nav_msgs/Odometry or geometry_msgs/PoseStamped "
        "topic instead of running KISS-ICP: each scan placed at the pose interpolated at its "
        "time (with --calib T, the scanner -> pose-frame transform: P_k T).")] = None,
    frame: TfFrame = None,
    calib: Annotated[Path | None, typer.Option(
        help="With --poses: scanner -> pose-frame transform T (12 or 16 numbers, or a KITTI "
        "calib.txt with Tr:); the map is then built in the first scanner's frame, "
        "inv(T) P_k T.")] = None,
    max_scans: Annotated[int | None, typer.Option(help="Use only the first N scans.", min=1)
                         ] = None,
    voxel: Annotated[float, typer.Option(help="Cell of the output map, metres.", min=1e-4,
                                         callback=options.finite)] = 0.1,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,
) -> None:
    from pcmapq.mapping import (
        build_map_from_poses,
        build_map_kiss,
        describe_scans,
        open_scans,
        recorded_poses,
        scanner_poses,
        scans_for_poses,
        write_kitti_poses,
        write_tum_poses,
    )

    err = Console(stderr=True)
    poses_out, tum_out = targets.kept(poses_out), targets.kept(tum_out)
    with report_errors(err), terminal.show_warnings(err):
        if calib is not None and poses is None and pose_topic is None:
            raise InputError(f"{calib}: --calib places scans with --poses or --pose-topic only "
                             "(KISS-ICP's map is in the first scanner's frame already)")
        if poses is not None and pose_topic is not None:
            raise InputError("--poses and --pose-topic: give one of the two")
        targets.check_outputs({"--out": out, "--poses-out": poses_out, "--tum-out": tum_out},
                              None, inputs=(source, poses, calib))
        with scan_bar(err, enabled=not quiet) as tick:
            if poses is None and pose_topic is None:
                if max_scans is not None and not quiet:
                    every = open_scans(source, topic=scan_topic)
                    first = replace(every, count=min(max_scans, len(every)),
                                    files=every.files[:max_scans])
                    err.print(f"mapping {describe_scans(first, len(every))}", markup=False,
                              highlight=False, soft_wrap=True)
                built, trajectory = build_map_kiss(source, max_scans=max_scans, voxel=voxel,
                                                   progress=tick, topic=scan_topic)
            else:
                trajectory = (scanner_poses(poses, calib) if poses is not None else
                              recorded_poses(source, scan_topic, pose_topic, calib, frame))
                every = open_scans(source, topic=scan_topic)
                scans = scans_for_poses(every, len(trajectory), max_scans=max_scans,
                                        poses_path=poses or pose_topic)
                if max_scans is not None and not quiet:
                    err.print(f"mapping {describe_scans(scans, len(every))}", markup=False,
                              highlight=False, soft_wrap=True)
                trajectory = trajectory[:len(scans)]
                built = build_map_from_poses(scans, trajectory, voxel=voxel, progress=tick)
        if not len(built):
            raise InputError(f"{source}: the scans hold no point to map (no return within "
                             "their range limits)")
        with OutputSet() as outputs:  # the map and its poses: all or none
            write_cloud(out, built.points, outputs, scan=built.scan)
            wrote = [f"wrote {out}: {count(len(built), 'point')} from "
                     f"{count(len(trajectory), 'scan')}"]
            if poses_out is not None:
                write_kitti_poses(poses_out, trajectory, outputs)
                wrote.append(f"wrote {poses_out}: {count(len(trajectory), 'pose')} (KITTI)")
            if tum_out is not None:
                write_tum_poses(tum_out, trajectory, outputs=outputs)
                wrote.append(f"wrote {tum_out}: {count(len(trajectory), 'pose')} (TUM)")
            outputs.commit()
    if not quiet:
        for line in wrote:
            err.print(line, markup=False, highlight=False, soft_wrap=True)
