"""The command line: parse options, call the pipeline, show and save the result. No logic."""

from __future__ import annotations

import json
import sys
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console

from pcmapq import __version__, gates, options
from pcmapq.config import (
    DETECTOR_NAMES,
    NoRefConfig,
    Settings,
)
from pcmapq.errors import InputError
from pcmapq.inspect_map import inspect_map, summary_lines, to_json
from pcmapq.io import PointMap, load_map
from pcmapq.io.writers import OutputSet, write_atomic, write_cloud
from pcmapq.mapping import (
    build_map_from_poses,
    build_map_kiss,
    describe_scans,
    lidar_poses_from_camera,
    moves_along_z,
    open_scans,
    posed_map,
    read_calib,
    read_pose_matrix,
    read_poses,
    scans_for_poses,
    write_kitti_poses,
    write_tum_poses,
)
from pcmapq.metrics.noref import DEPTH_RADIUS, LIDAR_RADIUS, MAX_NN, MIN_KNN
from pcmapq.metrics.posed import place_subset, read_orthogonal_subset
from pcmapq.pipeline import evaluate
from pcmapq.raster.footprint import FOOTPRINT_RULES
from pcmapq.report import export
from pcmapq.report.style import ARROW_SCALE
from pcmapq.report.table import print_table
from pcmapq.result import Result
from pcmapq.terminal import (
    HELP_WIDTH,
    OneLineUsageErrors,
    report_errors,
    scan_bar,
    show_warnings,
    step_progress,
)

#: The documented defaults, read from the one place that defines them.
DEFAULTS = Settings()

#: Help at the terminal's width (click caps it at 80 columns unless told otherwise), as plain
#: text: rich's markup would eat "[default: ...]" and squeeze the help into a narrow column.

app = typer.Typer(cls=OneLineUsageErrors, add_completion=False, no_args_is_help=True,
                  pretty_exceptions_enable=False, rich_markup_mode=None,
                  context_settings={"max_content_width": HELP_WIDTH},
                  help="Map quality against a ground-truth map, in metres.")


def _print_version(value: bool) -> None:
    """--version: print pcmapq's version and stop."""
    if value:
        print(f"pcmapq {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[bool, typer.Option(
        "--version", help="Print pcmapq's version and exit.", callback=_print_version,
        is_eager=True)] = False,
) -> None:
    """pcmapq: score a robot-made map against a ground-truth map (frame convention:
    p_truth = s * R(yaw) * p_map + t; metres and degrees). The scores are defined in
    docs/metrics.md."""


@app.command("map")
def map_command(
    source: Annotated[Path, typer.Argument(
        help="Scan sequence: a folder of KITTI .bin / .ply / .pcd / .npy scans, a ROS bag or "
        "an MCAP file.")],
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
    """Build a map from LiDAR scans with KISS-ICP (or with given poses) and save it."""
    err = Console(stderr=True)
    with report_errors(err), show_warnings(err):
        if calib is not None and poses is None:
            raise InputError(f"{calib}: --calib places scans with --poses only (KISS-ICP's "
                             "map is in the first scanner's frame already)")
        options.check_outputs({"--out": out, "--poses-out": poses_out, "--tum-out": tum_out},
                              None, inputs=(source, poses, calib))
        with scan_bar(err, enabled=not quiet) as tick:
            if poses is None:
                points, trajectory = build_map_kiss(source, max_scans=max_scans, voxel=voxel,
                                                    progress=tick)
            else:
                trajectory = read_poses(poses)
                if calib is not None:
                    trajectory = lidar_poses_from_camera(trajectory, read_calib(calib))
                elif moves_along_z(trajectory):
                    warnings.warn(f"{poses}: these poses move along their z axis, as a camera's "
                                  "do (KITTI's are the left camera's); without --calib (KITTI's "
                                  "Tr) the scans are placed as if they were the scanner's, and "
                                  "the map smears", stacklevel=1)
                every = open_scans(source)
                scans = scans_for_poses(every, len(trajectory), max_scans=max_scans,
                                        poses_path=poses)
                if max_scans is not None and not quiet:
                    err.print(f"mapping {describe_scans(scans, len(every))}", markup=False,
                              highlight=False, soft_wrap=True)
                trajectory = trajectory[:len(scans)]
                points = build_map_from_poses(scans, trajectory, voxel=voxel, progress=tick)
        with OutputSet() as outputs:  # the map and its poses: all or none
            write_cloud(out, points, outputs)
            wrote = [f"wrote {out}: {len(points)} points from {len(trajectory)} scans"]
            if poses_out is not None:
                write_kitti_poses(poses_out, trajectory, outputs)
                wrote.append(f"wrote {poses_out}: {len(trajectory)} poses (KITTI)")
            if tum_out is not None:
                write_tum_poses(tum_out, trajectory, outputs=outputs)
                wrote.append(f"wrote {tum_out}: {len(trajectory)} poses (TUM)")
            outputs.commit()
    if not quiet:
        for line in wrote:
            err.print(line, markup=False, highlight=False, soft_wrap=True)


@app.command("inspect")
def inspect_command(
    ctx: typer.Context,
    map_path: Annotated[Path | None, typer.Argument(
        metavar="[MAP]", help="Map to inspect: cloud (.ply/.pcd/.xyz/.npy/.bin), CARMEN log, or "
        "image (.png/.pgm with its ROS YAML, or the YAML). Or --scans with --poses.",
        show_default=False)] = None,
    scans: Annotated[Path | None, typer.Option(
        help="Inspect these scans placed at --poses instead: a folder of .bin/.ply/.pcd/.npy "
        "scans, a ROS bag or an MCAP file.")] = None,
    poses: Annotated[Path | None, typer.Option(
        help="With --scans: one pose per scan, a KITTI or TUM file or a folder of 4x4 text "
        "files (name order); the map is in the first scan's frame.")] = None,
    radius: Annotated[float, typer.Option(
        help=f"Neighbourhood radius of MME, MPV and MOM, metres ({LIDAR_RADIUS:g} for LiDAR "
        f"maps, {DEPTH_RADIUS:g} for depth cameras).", min=1e-6,
        callback=options.finite)] = LIDAR_RADIUS,
    min_knn: Annotated[int, typer.Option(
        help="A point counts when it has more than this many neighbours.", min=0)] = MIN_KNN,
    max_nn: Annotated[int, typer.Option(
        help="Nearest neighbours of the normals that pick MOM's orthogonal planes.", min=3)
    ] = MAX_NN,
    voxel: Annotated[float, typer.Option(
        help="First reduce a 3D cloud to one point (the centroid) per cell of this size, "
        "metres; 0: as it is, as map-metrics ('pcmapq eval' uses 0.1).", min=0.0,
        callback=options.finite)] = 0.0,
    orth_subset: Annotated[Path | None, typer.Option(
        help="MOM's orthogonal planes (a map-metrics .npy or .npz) in the map's frame, or in "
        "the frame of the scan at --orth-pose; otherwise pcmapq extracts them.")] = None,
    orth_pose: Annotated[Path | None, typer.Option(
        help="With --orth-subset: the 4x4 pose of the scan whose frame the planes are in "
        "(with --poses, placed relative to the first pose, as the map).")] = None,
    map_resolution: Annotated[float | None, typer.Option(
        help="Metres per pixel of an image without YAML.", min=1e-6, callback=options.finite)
    ] = None,
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Write the figures as JSON to this path ('-' for stdout only).")] = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,
) -> None:
    """How good is a map without a ground truth: MME, MPV and MOM of a 3D cloud, occupancy
    figures of a 2D map (docs/metrics.md)."""
    err = Console(stderr=True)
    with report_errors(err), show_warnings(err):
        if (map_path is None) == (scans is None) or (scans is None) != (poses is None):
            raise typer.BadParameter("give MAP, or --scans DIR with --poses FILE",
                                     param_hint="MAP")
        if orth_pose is not None and orth_subset is None:
            raise typer.BadParameter("--orth-pose places --orth-subset: give both",
                                     param_hint="--orth-pose")
        options.check_outputs({"--json": json_path}, None,
                              inputs=(map_path, scans, poses, orth_subset, orth_pose))
        first = np.eye(4)
        if scans is not None and poses is not None:
            trajectory = read_poses(poses)
            first = trajectory[0]
            source = PointMap(scans, posed_map(scans, trajectory), True, kind="scans")
        else:
            source = load_map(map_path, map_resolution)
        planes = None if orth_subset is None else read_orthogonal_subset(orth_subset)
        if planes is not None and orth_pose is not None:
            planes = place_subset(planes, read_pose_matrix(orth_pose), first)
        config = NoRefConfig(radius=radius, min_knn=min_knn, max_nn=max_nn, voxel=voxel)
        record = inspect_map(source, config, planes, options.command_line(ctx))
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



#: The CI gates of eval and batch (a batch judges every row; docs/ci.md).
FailUnder = Annotated[str | None, typer.Option(
    metavar="<KEY=VALUE,...>",
    help="CI gate: exit 3 when a figure (of any row, in a batch) is below its bound, e.g. "
    "harris.quality=0.8,coverage=0.9 (keys: docs/ci.md; a figure that is n/a fails). The "
    "outputs are written all the same.")]
FailOver = Annotated[str | None, typer.Option(
    metavar="<KEY=VALUE,...>",
    help="CI gate for distances: exit 3 when a figure is above its bound, e.g. "
    "accuracy.mean=0.05 (metres).")]


@app.command("eval")
def eval_command(
    ctx: typer.Context,
    paths: Annotated[list[Path], typer.Argument(
        metavar="MAP TRUTH", help="Map to score: image (.png/.pgm, with its ROS YAML), YAML, "
        "cloud (.ply/.pcd/.xyz/.npy/.bin) or CARMEN log; then the ground truth, same kinds. "
        "With --scans, TRUTH only.")],
    scans: Annotated[Path | None, typer.Option(
        help="Build the map from this scan sequence with KISS-ICP (see 'pcmapq map') and "
        "score it.")] = None,
    max_scans: Annotated[int | None, typer.Option(
        help="With --scans: use only the first N scans.", min=1)] = None,
    map_resolution: Annotated[str | None, typer.Option(
        metavar="<metres|auto>",
        help="Metres per pixel of a map image without YAML (overrides its YAML); 'auto' "
        "estimates the map's scale (same as --scale auto).")] = None,
    scale: Annotated[str, typer.Option(
        metavar="<fixed|auto>",
        help="'fixed': the map's metres are metres; 'auto': estimate its scale too (a "
        "similarity), for maps whose resolution is unknown.")] = "fixed",
    truth_resolution: Annotated[float | None, typer.Option(
        help="Metres per pixel of a truth image without YAML; cell size for a cloud truth "
        "(default 0.05).", min=1e-6, callback=options.finite)] = None,
    map_occupied_thresh: Annotated[float | None, typer.Option(
        help="Map image: occupied if p > this (map_server's occupied_thresh; overrides the "
        "YAML's, default 0.65).", min=0.0, max=1.0, show_default=False,
        callback=options.finite)] = None,
    map_free_thresh: Annotated[float | None, typer.Option(
        help="Map image: free if p < this (map_server's free_thresh; overrides the YAML's, "
        "default 0.196).", min=0.0, max=1.0, show_default=False, callback=options.finite)] = None,
    map_negate: Annotated[bool | None, typer.Option(
        "--map-negate/--map-no-negate", help="Map image: p = v / 255 instead of (255 - v) / 255 "
        "(map_server's negate; overrides the YAML's).", show_default=False)] = None,
    truth_occupied_thresh: Annotated[float | None, typer.Option(
        help="Truth image: as --map-occupied-thresh.", min=0.0, max=1.0,
        show_default=False, callback=options.finite)] = None,
    truth_free_thresh: Annotated[float | None, typer.Option(
        help="Truth image: as --map-free-thresh.", min=0.0, max=1.0, show_default=False,
        callback=options.finite)
    ] = None,
    truth_negate: Annotated[bool | None, typer.Option(
        "--truth-negate/--truth-no-negate", help="Truth image: as --map-negate.",
        show_default=False)] = None,
    map_crop: Annotated[str | None, typer.Option(
        metavar="<x0,y0,x1,y1>", help="Keep only the map's part inside this box, metres, in "
        "its own frame (outlier points far away).")] = None,
    truth_crop: Annotated[str | None, typer.Option(
        metavar="<x0,y0,x1,y1>", help="Keep only the truth's part inside this box, metres, in "
        "its own frame.")] = None,
    init: Annotated[str | None, typer.Option(
        help="Initial guess x,y,yaw (m, m, deg), map -> truth; skips the global search.")] = None,
    no_align: Annotated[bool, typer.Option(
        "--no-align", help="Trust the map's frame: no alignment at all.")] = False,
    force: Annotated[bool, typer.Option(
        help="Evaluate even when the map does not seem to show the truth's place.")] = False,
    threshold: Annotated[float, typer.Option(
        help="Largest distance between matched features, metres.", min=1e-6,
        callback=options.finite)
    ] = DEFAULTS.matching.threshold,
    band_low: Annotated[float, typer.Option(
        help="Wall band of a 3D cloud: lower bound, metres above the floor.",
        callback=options.finite)
    ] = DEFAULTS.raster.band_low,
    band_high: Annotated[float, typer.Option(
        help="Wall band of a 3D cloud: upper bound, metres above the floor.",
        callback=options.finite)
    ] = DEFAULTS.raster.band_high,
    min_hits: Annotated[int | None, typer.Option(
        help="Points needed to mark a cloud's cell occupied (default: 2 for a 3D cloud, 1 for "
        "a 2D one).", min=1, show_default=False)] = None,
    detectors: Annotated[str, typer.Option(
        metavar="<" + ",".join(DEFAULTS.matching.detectors) + ">",
        help="Comma-separated detectors to run, any of "
        f"{', '.join(DETECTOR_NAMES)}.")] = ",".join(DEFAULTS.matching.detectors),
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Write the result as JSON to this path ('-' for stdout only).")] = None,
    vectors: Annotated[Path | None, typer.Option(
        help="Write the vectorial map as CSV: one row per matched pair of features (truth and "
        "map position, displacement, metres) and which of its two features are counted "
        "(truth_counted, map_counted: 1 or 0).")] = None,
    plot: Annotated[Path | None, typer.Option(
        help="Draw the vectorial map, one panel per detector, as PNG.")] = None,
    report: Annotated[Path | None, typer.Option(
        help="Write a self-contained HTML report (figures embedded).")] = None,
    arrow_scale: Annotated[float, typer.Option(
        help="Displacement arrows of --plot and --report are drawn this many times their "
        "length, in every panel of every run.", min=1e-6, callback=options.finite)] = ARROW_SCALE,
    voxel_3d: Annotated[float, typer.Option(
        "--voxel-3d", help="Working voxel of the 3D registration of two 3D clouds, metres "
        "(0.5-1 for outdoor maps).", min=0.01,
        callback=options.finite)] = DEFAULTS.alignment.voxel_3d,
    tau: Annotated[str, typer.Option(
        help="Distance thresholds of the F-score, metres, comma-separated.")
    ] = ",".join(f"{t:g}" for t in DEFAULTS.distances.taus),
    footprint: Annotated[str, typer.Option(
        metavar="<" + "|".join(FOOTPRINT_RULES) + ">",
        help="The area the map observed: 'known' cells of an image, the area its 'walls' "
        "enclose, 'all' of its rectangle; 'auto': known cells for an image with unknown "
        "regions, walls for a binary image or a cloud.")] = DEFAULTS.footprint.rule,
    full: Annotated[bool, typer.Option(
        "--full", help="Score against the whole truth, not only the part the map covers.")
    ] = False,
    max_memory: Annotated[float | None, typer.Option(
        help="Stop (exit 2) before a run estimated to need more than this many GB "
        "(default: 75 % of this machine's memory).", min=0.0, show_default=False,
        callback=options.finite)] = None,
    aligned: Annotated[Path | None, typer.Option(
        help="Write the map moved into the truth's frame: .ply/.pcd for a cloud map (a 3D "
        "cloud keeps its heights), .png/.pgm with its map_server YAML for an image map.")
    ] = None,
    transform: Annotated[Path | None, typer.Option(
        help="Write the map -> truth matrix as plain text (.txt): 4x4 for a 3D cloud map, 3x3 "
        "for a 2D map (np.loadtxt, CloudCompare).")] = None,
    distances: Annotated[Path | None, typer.Option(
        help="Write the map's points in the truth's frame with their distance to the truth "
        "(.ply: scalar field scalar_distance_m, metres, and a colour).")] = None,
    noref: Annotated[bool, typer.Option(
        "--noref/--no-noref", help="Also report each input's no-reference figures, as "
        "'pcmapq inspect' does (MME, MPV, MOM of a 3D cloud; occupancy figures of a 2D map).")
    ] = DEFAULTS.noref.enabled,
    noref_radius: Annotated[float, typer.Option(
        help="Neighbourhood of the 3D no-reference figures, metres (0.2 for depth-camera "
        "maps, with --noref-voxel 0.02).", min=1e-6, callback=options.finite)
    ] = DEFAULTS.noref.radius,
    noref_voxel: Annotated[float, typer.Option(
        help="A 3D cloud is first reduced to one point per cell of this size for its "
        "no-reference figures, metres (0: as it is).", min=0.0, callback=options.finite)
    ] = DEFAULTS.noref.voxel,
    fail_under: FailUnder = None,
    fail_over: FailOver = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors (and the JSON of "
        "--json -).")] = False,
) -> None:
    """Align MAP to TRUTH, then score it with Harris, Hough and SIFT features."""
    if len(paths) != (1 if scans else 2):
        raise typer.BadParameter("give MAP and TRUTH, or --scans DIR and TRUTH",
                                 param_hint="MAP TRUTH")
    truth_path = paths[-1]
    settings = options.eval_settings(dict(
        map_resolution=map_resolution, scale=scale, truth_resolution=truth_resolution,
        map_occupied_thresh=map_occupied_thresh, map_free_thresh=map_free_thresh,
        map_negate=map_negate, truth_occupied_thresh=truth_occupied_thresh,
        truth_free_thresh=truth_free_thresh, truth_negate=truth_negate, map_crop=map_crop,
        truth_crop=truth_crop, init=init, no_align=no_align, force=force, threshold=threshold,
        band_low=band_low, band_high=band_high, min_hits=min_hits, detectors=detectors,
        voxel_3d=voxel_3d, tau=tau, footprint=footprint, full=full, noref=noref,
        noref_radius=noref_radius, noref_voxel=noref_voxel))
    auto = settings.alignment.scale
    exports = {"--aligned": aligned, "--transform": transform, "--distances": distances}
    err = Console(stderr=True)
    out = Console(quiet=quiet or json_path == "-")  # not a terminal: COLUMNS or 80 wide
    with report_errors(err), show_warnings(err), \
            step_progress(err, enabled=not quiet and json_path != "-") as progress:
        rules = gates.parse_rules(fail_under, fail_over)
        options.check_eval_options(scans=scans, max_scans=max_scans, no_align=no_align,
                                   auto_scale=auto)
        options.check_outputs({"--json": json_path, "--vectors": vectors, "--plot": plot,
                               "--report": report, **exports}, None if scans else paths[0],
                              inputs=paths)
        if scans is None:
            map_path: Path | PointMap = paths[0]
        else:
            progress("mapping the scans with KISS-ICP")
            points, _ = build_map_kiss(scans, max_scans=max_scans)
            map_path = PointMap(scans, points, True, kind="scans")
        limit = None if max_memory is None else int(max_memory * 1e9)
        result = replace(evaluate(map_path, truth_path, settings, progress, limit),
                         command=options.command_line(ctx))
        doc = result.to_dict() if rules else {}
        outcomes = gates.check(rules, doc)  # an unknown key: exit 2, before any output
        json_text = gates.to_json(gates.with_gates(doc, outcomes)) if rules else None
        progress("writing outputs")
        wrote = _write_outputs(result, map_path, settings, arrow_scale, json_path=json_path,
                               vectors=vectors, plot=plot, report=report, exports=exports,
                               json_text=json_text)
        if json_path == "-":
            sys.stdout.write(json_text or result.to_json())
    if not quiet:
        for path in wrote:
            err.print(f"wrote {path}", markup=False, highlight=False, soft_wrap=True)
    print_table(result, out)
    if failed := [o.line() for o in outcomes if not o.passed]:  # a verdict, not an error
        for line in failed:
            err.print(f"pcmapq: gate failed: {line}", markup=False, highlight=False,
                      soft_wrap=True)
        raise typer.Exit(gates.EXIT_CODE)


def _write_outputs(result: Result, map_path: Path | PointMap, settings: Settings,
                   arrow_scale: float, *, json_path: str | None, vectors: Path | None,
                   plot: Path | None, report: Path | None,
                   exports: dict[str, Path | None], json_text: str | None = None) -> list[Path]:
    """Write the run's output files, all or nothing: each is produced into a temporary file
    beside its target, and all are renamed into place only once every one is produced
    (:class:`OutputSet`); the JSON is ``json_text`` when given (with gates), else the result's.
    The files written (an ``--aligned`` image's YAML too)."""
    with OutputSet() as outputs:
        wrote: list[Path] = []
        if json_path not in (None, "-"):
            write_atomic(Path(json_path), json_text or result.to_json(), outputs)
            wrote.append(Path(json_path))
        if vectors is not None:
            write_atomic(vectors, result.vectors_csv(), outputs)
            wrote.append(vectors)
        if plot is not None or report is not None:
            from pcmapq.report.html import report_html
            from pcmapq.report.plot import figure_bytes, vectorial_figure
        if plot is not None:
            write_atomic(plot, figure_bytes(vectorial_figure(result, arrow_scale),
                                            plot.suffix.lower()[1:]), outputs)
            wrote.append(plot)
        if report is not None:
            write_atomic(report, report_html(result, arrow_scale), outputs)
            wrote.append(report)
        wrote += export.write_exports(result, map_path, settings, aligned=exports["--aligned"],
                                      transform=exports["--transform"],
                                      distances=exports["--distances"], outputs=outputs)
        outputs.commit()
    return wrote


@app.command("compare")
def compare_command(
    results: Annotated[list[Path], typer.Argument(
        metavar="RESULTS...", help="Saved results: JSON files of 'pcmapq eval --json' (or of "
        "a batch), one row each.")],
    out: Annotated[Path, typer.Option(
        help="Folder to write table.csv, table.md and figure.png into (made if missing).")],
    names: Annotated[str | None, typer.Option(
        help="Comma-separated row names, one per result (default: each file's stem).")
    ] = None,
    allow_different_truths: Annotated[bool, typer.Option(
        "--allow-different-truths", help="Compare results scored against different truths "
        "(a warning instead of exit 2).")] = False,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,
) -> None:
    """Compare saved results side by side (like evo_res): a table and a figure of the
    qualities, precisions, f1, coverage, alignment and wall distances (metres, degrees)."""
    from pcmapq.compare import check_same_truth, read_results
    from pcmapq.report.summary import print_summary, write_summary

    err = Console(stderr=True)
    with report_errors(err), show_warnings(err):
        saved = read_results(results, None if names is None else names.split(","))
        if (line := check_same_truth(saved, allow_different_truths)) is not None:
            warnings.warn(line, stacklevel=1)
        rows = [s.row for s in saved]
        wrote = write_summary(rows, out)
    if not quiet:
        for path in wrote:
            err.print(f"wrote {path}", markup=False, highlight=False, soft_wrap=True)
        print_summary(rows, Console())


@app.command("batch")
def batch_command(
    sources: Annotated[list[str], typer.Argument(
        metavar="MANIFEST | MAP...", help="A manifest (.csv, .yaml or .yml: one row per "
        "evaluation, columns map, truth, name and eval's options; relative paths from its "
        "folder), or with --truth: maps or quoted globs ('maps/*.png').")],
    out: Annotated[Path, typer.Option(
        help="Folder of the results: NAME.json per row (as eval --json), table.csv, table.md, "
        "figure.png.")],
    truth: Annotated[Path | None, typer.Option(
        help="The ground truth of every map given as MAP... (a glob's maps).")] = None,
    set_options: Annotated[list[str] | None, typer.Option(
        "--set", metavar="KEY=VALUE", help="An eval option for every row, by its manifest "
        "column (threshold=0.3, scale=auto ...); a row's own cell wins. Repeatable.")] = None,
    workers: Annotated[int | None, typer.Option(
        help="Local worker processes (default: one per core).", min=1,
        show_default=False)] = None,
    scheduler: Annotated[str | None, typer.Option(
        metavar="ADDRESS", help="Run the rows on this dask.distributed cluster "
        "(tcp://HOST:8786) instead; its workers must see the inputs and --out at the same "
        "paths. Needs pip install 'pcmapq[cluster]'.")] = None,
    force: Annotated[bool, typer.Option(
        "--force", help="Recompute every row, even one whose saved result is valid.")
    ] = False,
    plot: Annotated[bool, typer.Option(
        "--plot", help="Draw each row's vectorial map too: NAME.png.")] = False,
    report: Annotated[bool, typer.Option(
        "--report", help="Write each row's HTML report too: NAME.html.")] = False,
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Write how each row ended as JSON to this path ('-' for stdout only)."
    )] = None,
    fail_under: FailUnder = None,
    fail_over: FailOver = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,
) -> None:
    """Evaluate many maps, on local processes or a Dask cluster: a result per row, a table
    and a figure of them all; a rerun skips the rows already done. Exit 1 if any row failed,
    else 3 if a row failed a gate."""
    from pcmapq.batch import glob_rows, parse_assignments, read_rows, run_batch
    from pcmapq.batch.progress import row_bar

    err = Console(stderr=True)
    with report_errors(err), show_warnings(err):
        if workers is not None and scheduler is not None:
            raise InputError("--workers sets local processes; with --scheduler the cluster's "
                             "workers run the rows: give one of the two")
        rules = gates.parse_rules(fail_under, fail_over)
        defaults = parse_assignments(set_options or [])
        if truth is not None:
            if any(s.lower().endswith(".csv") for s in sources):
                raise InputError("--truth gives the truth of maps given as MAP...; a "
                                 "manifest's rows name their own ('truth' column, or --set "
                                 "truth=FILE)")
            rows = glob_rows(sources, truth, defaults)
        elif len(sources) == 1:
            rows = read_rows(Path(sources[0]), defaults)
        else:
            raise typer.BadParameter("give one manifest, or maps with --truth",
                                     param_hint="MANIFEST | MAP...")
        if out.exists() and not out.is_dir():
            raise InputError(f"{out}: --out: not a folder")
        if json_path not in (None, "-"):
            out.mkdir(parents=True, exist_ok=True)  # --json may go into it
            options.check_outputs({"--json": json_path}, None, inputs=())
            if any(options.same_file(Path(json_path), out / f"{r.name}.json") for r in rows):
                raise InputError(f"{json_path}: --json would overwrite a row's result")
        with row_bar(err, len(rows), enabled=not quiet and json_path != "-") as tick:
            outcomes = run_batch(rows, out, plot=plot, report=report, force=force,
                                 workers=workers, scheduler=scheduler, done=tick,
                                 rules=rules)
        codes = {o.exit_code for o in outcomes}
        code = 1 if codes - {0, gates.EXIT_CODE} else max(codes)
        doc = {"out": str(out), "exit_code": code,
               "rows": [{"name": o.name, "status": o.status, "exit_code": o.exit_code,
                         "error": o.error,
                         "result": None if o.exit_code else str(out / f"{o.name}.json")}
                        for o in outcomes]}
        text = json.dumps(doc, indent=2) + "\n"
        if json_path not in (None, "-"):
            with OutputSet() as outputs:
                write_atomic(Path(json_path), text, outputs)
                outputs.commit()
    for o in outcomes:
        for line in o.warnings:
            err.print(f"pcmapq: warning: {o.name}: {line}", markup=False, highlight=False,
                      soft_wrap=True)
        if o.exit_code == gates.EXIT_CODE:
            err.print(f"pcmapq: gate failed: {o.name}: {o.error}", markup=False,
                      highlight=False, soft_wrap=True)
        elif o.exit_code:
            err.print(f"pcmapq: error: {o.name}: {o.error} (exit {o.exit_code})", markup=False,
                      highlight=False, soft_wrap=True)
    if json_path == "-":
        sys.stdout.write(text)
    elif not quiet:
        counts = {s: sum(o.status == s for o in outcomes) for s in ("computed", "skipped",
                                                                    "failed")}
        gated = sum(o.exit_code == gates.EXIT_CODE for o in outcomes)
        err.print(f"{len(outcomes)} rows: " + ", ".join(f"{n} {s}" for s, n in counts.items())
                  + (f", {gated} failing a gate" if rules else "")
                  + f"; wrote {out / 'table.csv'}, table.md, figure.png", markup=False,
                  highlight=False, soft_wrap=True)
    if code:
        raise typer.Exit(code)


@app.command("track")
def track_command(
    ctx: typer.Context,
    paths: Annotated[list[Path], typer.Argument(
        metavar="RUN TRUTH", help="The run: a CARMEN log (.log/.log.gz), or scans (a folder of "
        ".bin/.ply/.pcd/.npy scans, a ROS bag, an MCAP file); then the ground truth, as "
        "eval's.")],
    out: Annotated[Path, typer.Option(
        help="Folder of the results: track.csv, track.json, track.png, track.html.")],
    poses: Annotated[Path | None, typer.Option(
        help="The run's estimated poses, one per scan (KITTI or TUM file); default: a log's "
        "own, KISS-ICP's for scans.")] = None,
    reference_poses: Annotated[Path | None, typer.Option(
        help="Reference poses, one per scan (KITTI or TUM file, or a CARMEN log's): adds the "
        "trajectory's APE and RPE at every step, as evo computes them.")] = None,
    every: Annotated[int | None, typer.Option(
        help="Score the map every N scans (default 20).", min=1, show_default=False)] = None,
    every_m: Annotated[float | None, typer.Option(
        help="Score the map every D metres travelled instead.", min=1e-6,
        callback=options.finite)] = None,
    step: Annotated[int | None, typer.Option(
        help="The step the report shows (default: where the worst drop starts).", min=0,
        show_default=False)] = None,
    align_poses: Annotated[bool, typer.Option(
        "--align-poses", help="APE/RPE: align the poses first (SE(3) Umeyama, evo's -a).")
    ] = False,
    correct_scale: Annotated[bool, typer.Option(
        "--correct-scale", help="APE/RPE: correct the scale too (evo's -s).")] = False,
    delta: Annotated[int, typer.Option(help="RPE: pairs this many scans apart.", min=1)] = 1,
    truth_resolution: Annotated[float | None, typer.Option(
        help="As eval's.", min=1e-6, callback=options.finite)] = None,
    init: Annotated[str | None, typer.Option(
        help="Initial guess x,y,yaw (m, m, deg), map -> truth, of the first step; skips the "
        "global search.")] = None,
    no_align: Annotated[bool, typer.Option(
        "--no-align", help="Trust the run's frame: no alignment at any step.")] = False,
    force: Annotated[bool, typer.Option(
        help="Score every step, even one that does not seem to show the truth's place.")
    ] = False,
    threshold: Annotated[float, typer.Option(
        help="Largest distance between matched features, metres.", min=1e-6,
        callback=options.finite)] = DEFAULTS.matching.threshold,
    detectors: Annotated[str, typer.Option(
        metavar="<" + ",".join(DEFAULTS.matching.detectors) + ">",
        help="As eval's.")] = ",".join(DEFAULTS.matching.detectors),
    footprint: Annotated[str, typer.Option(
        metavar="<" + "|".join(FOOTPRINT_RULES) + ">",
        help="As eval's; 'auto' is 'seen': the area the scans so far saw.")
    ] = DEFAULTS.footprint.rule,
    tau: Annotated[str, typer.Option(
        help="Distance thresholds of the F-score and wall precision, metres.")
    ] = ",".join(f"{t:g}" for t in DEFAULTS.distances.taus),
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Also write track.json to this path ('-' for stdout only).")] = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,
) -> None:
    """Score a SLAM run's map as it grows, every N scans or D metres, against the truth:
    when did the map go wrong, and where was the robot then?"""
    from pcmapq.track import PoseOptions, step_ends, track_run, travelled, write_track
    from pcmapq.track.runs import open_run, reference_poses_of

    if len(paths) != 2:
        raise typer.BadParameter("give RUN and TRUTH", param_hint="RUN TRUTH")
    run_path, truth_path = paths
    settings = options.eval_settings(dict(
        truth_resolution=truth_resolution, init=init, no_align=no_align, force=force,
        threshold=threshold, detectors=detectors, footprint=footprint, tau=tau))
    err = Console(stderr=True)
    shown = not quiet and json_path != "-"
    with report_errors(err), show_warnings(err), step_progress(err, enabled=shown) as progress:
        if every is not None and every_m is not None:
            raise typer.BadParameter("give one of --every and --every-m", param_hint="--every")
        if out.exists() and not out.is_dir():
            raise InputError(f"{out}: --out: not a folder")
        options.check_outputs({"--json": json_path}, None, inputs=paths)
        with scan_bar(err, enabled=shown) as tick:
            run = open_run(run_path, poses, progress=tick)
        reference = (None if reference_poses is None
                     else reference_poses_of(reference_poses, len(run)))
        ends = step_ends(len(run), (every or 20) if every_m is None else None, every_m,
                         travelled(run.poses))
        tracked = track_run(run, truth_path, settings, ends, reference=reference,
                            pose_options=PoseOptions(align_poses, correct_scale, delta),
                            show=step, progress=progress,
                            tick=lambda done: progress(f"scoring: {done} of {len(run)} scans"))
        rule = {"every_scans": None if every_m is not None else (every or 20),
                "every_m": every_m}
        wrote = write_track(tracked, out, rule, options.command_line(ctx))
        if json_path not in (None, "-"):
            with OutputSet() as outputs:
                write_atomic(Path(json_path), wrote[1].read_text(), outputs)
                outputs.commit()
    scored = sum(s.scored for s in tracked.steps)
    if json_path == "-":
        sys.stdout.write(wrote[1].read_text())
    elif not quiet:
        drop = tracked.drop
        err.print(f"{len(tracked.steps)} steps ({scored} scored) of {len(run)} scans; "
                  + ("no drop" if drop is None else
                     f"worst drop of {drop.figure}: {drop.size:.3f} from step {drop.start} "
                     f"({tracked.steps[drop.start].distance_m:.0f} m travelled)")
                  + f"; wrote {out}/track.csv, track.json, track.png, track.html",
                  markup=False, highlight=False, soft_wrap=True)
    if not scored:  # nothing to measure: said as such, and not a success
        err.print(f"pcmapq: error: {run_path}: no step could be scored; the last: "
                  f"{tracked.steps[-1].note}", markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(1)
