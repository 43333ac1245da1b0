"""``pcmapq eval``: one map against its truth. The pipeline, the mapping and the reports are
imported when the command runs, not when its help is shown (tests/cli/test_startup.py)."""

from __future__ import annotations

import sys
import warnings
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console

from pcmapq.cli import options, terminal
from pcmapq.cli.commands import (
    HELP,
    FailOver,
    FailUnder,
    MaxMemory,
    ScanTopic,
    app,
    memory_limit,
)
from pcmapq.cli.terminal import (
    report_errors,
    step_progress,
)
from pcmapq.core.errors import InputError
from pcmapq.io import targets
from pcmapq.io.formats import map_formats, scan_formats
from pcmapq.io.writers import OutputSet, write_atomic
from pcmapq.report.style import ARROW_SHARE, MAX_ARROW_SCALE
from pcmapq.results import gates
from pcmapq.settings import (
    Settings,
)

if TYPE_CHECKING:
    from pcmapq.io import PointMap
    from pcmapq.results.result import Result


@app.command("eval", help=HELP["eval"])
@options.settings_options("eval")
def eval_command(
    ctx: typer.Context,
    paths: Annotated[list[Path], typer.Argument(
        metavar="MAP TRUTH", help=f"Map to score: {map_formats()}; then the ground truth, "
        "same kinds. With --scans, TRUTH only.")],
    scans: Annotated[Path | None, typer.Option(
        help=f"Build the map from this scan sequence (a folder of {scan_formats()} scans, or a "
        "ROS recording) with KISS-ICP (see 'pcmapq map') and score it.")] = None,
    max_scans: Annotated[int | None, typer.Option(
        help="With --scans: use only the first N scans.", min=1)] = None,
    scan_topic: ScanTopic = None,
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Write the result as JSON to this path ('-' for stdout only).")] = None,
    vectors: Annotated[Path | None, typer.Option(
        help="Write the vectorial map as CSV: one row per matched pair of features (truth and "
        "map position, displacement, metres) and which of its two features are counted "
        "(truth_counted, map_counted: 1 or 0).")] = None,
    regions: Annotated[Path | None, typer.Option(
        help="Write the consistency map as CSV: one row per region of the map (truth frame, "
        "metres), the offset and turn (degrees) that fit it to the truth on its own, its "
        "points, its fitness before and after, and whether its walls hold it (held).")] = None,
    regions_3d: Annotated[Path | None, typer.Option(
        "--regions-3d", help="Two 3D clouds: write the 3D consistency map as CSV, one row per "
        "tile of the ground, or per stretch of the run for a map that carries its points' "
        "scans (truth frame levelled, metres): where the map has the region from where it "
        "fits the truth on its own (dx, dy, dz; roll, pitch, yaw in degrees), its points, its "
        "fitness before and after, and whether it is held.")] = None,
    plot: Annotated[Path | None, typer.Option(
        help="Draw the vectorial map, one panel per detector: PNG, SVG or PDF by the file's "
        "extension.")] = None,
    report: Annotated[Path | None, typer.Option(
        help="Write a self-contained HTML report (figures embedded).")] = None,
    arrow_scale: Annotated[float | None, typer.Option(
        help="Draw the displacement arrows of --plot and --report this many times their "
        f"length, in every panel (default: a round scale, 1 to {MAX_ARROW_SCALE:g}, that "
        f"draws the longest arrow within {ARROW_SHARE * 100:g}\u00a0% of a panel's larger "
        "side; stated in the legend).", min=1e-6, callback=options.finite,
        show_default=False)] = None,
    max_memory: MaxMemory = None,
    aligned: Annotated[Path | None, typer.Option(
        help="Write the map moved into the truth's frame: .ply/.pcd for a cloud map (a 3D "
        "cloud keeps its heights), .png/.pgm with its map_server YAML for an image map.")
    ] = None,
    transform: Annotated[Path | None, typer.Option(
        help="Write the map -> truth matrix as plain text (.txt), 4x4 as CloudCompare and "
        "np.loadtxt read it: a 2D map's plan similarity with z scaled alike (the JSON's "
        "alignment.matrix is its 3x3).")] = None,
    distances: Annotated[Path | None, typer.Option(
        help="Write the map's points in the truth's frame with their distance to the truth "
        "(.ply: scalar field scalar_distance_m, metres, and a colour).")] = None,
    fail_under: FailUnder = None,
    fail_over: FailOver = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors (and the JSON of "
        "--json -).")] = False,

    **settings_values: Any,
) -> None:
    from pcmapq.evaluation.pipeline import evaluate
    from pcmapq.io.clouds import PointMap
    from pcmapq.mapping import build_map_kiss
    from pcmapq.report.table import print_table

    if len(paths) != (1 if scans else 2):
        raise typer.BadParameter("give MAP and TRUTH, or --scans DIR and TRUTH",
                                 param_hint="MAP TRUTH")
    truth_path = paths[-1]
    json_path, vectors, regions, regions_3d, plot, report, aligned, transform, distances = (
        targets.kept(p) for p in (json_path, vectors, regions, regions_3d, plot, report, aligned,
                                  transform, distances))
    exports = {"--aligned": aligned, "--transform": transform, "--distances": distances}
    err = Console(stderr=True)
    out = Console(quiet=quiet or json_path == "-")  # not a terminal: COLUMNS or 80 wide
    with report_errors(err), terminal.show_warnings(err), \
            step_progress(err, enabled=not quiet and json_path != "-") as progress:
        settings = options.settings_of(ctx, "eval", settings_values)
        rules = gates.parse_rules(fail_under, fail_over)
        if (max_scans is not None or scan_topic is not None) and scans is None:
            raise InputError(f"{'--max-scans N' if max_scans is not None else '--scan-topic'}"
                             ": only with --scans DIR (the scans to map)")
        targets.check_outputs({"--json": json_path, "--vectors": vectors,
                               "--regions": regions, "--regions-3d": regions_3d,
                               "--plot": plot,
                               "--report": report, **exports}, None if scans else paths[0],
                              inputs=(*paths, settings_values.get("config")))
        if scans is None:
            map_path: Path | PointMap = paths[0]
        else:
            progress("mapping the scans with KISS-ICP")
            built, _ = build_map_kiss(scans, max_scans=max_scans, topic=scan_topic)
            map_path = PointMap.of_scans(scans, built.points, built.scan)
        limit = memory_limit(max_memory)
        result = replace(evaluate(map_path, truth_path, settings, progress, limit),
                         command=options.command_line(ctx))
        doc = result.to_dict() if rules else {}
        outcomes = gates.check(rules, doc)  # an unknown key: exit 2, before any output
        json_text = gates.to_json(gates.with_gates(doc, outcomes)) if rules else None
        progress("writing outputs")
        wrote = _write_outputs(result, map_path, settings, arrow_scale, json_path=json_path,
                               vectors=vectors, regions=regions, regions_3d=regions_3d,
                               plot=plot, report=report, exports=exports, json_text=json_text)
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
                   arrow_scale: float | None, *, json_path: str | None, vectors: Path | None,
                   regions: Path | None, plot: Path | None, report: Path | None,
                   exports: dict[str, Path | None], json_text: str | None = None,
                   regions_3d: Path | None = None) -> list[Path]:
    """Write the run's output files, all or nothing: each is produced into a temporary file
    beside its target, and all are renamed into place only once every one is produced
    (:class:`OutputSet`); the JSON is ``json_text`` when given (with gates), else the result's.
    The files written (an ``--aligned`` image's YAML too)."""
    from pcmapq.report import export

    with OutputSet() as outputs:
        wrote: list[Path] = []
        if json_path not in (None, "-"):
            write_atomic(Path(json_path), json_text or result.to_json(), outputs)
            wrote.append(Path(json_path))
        if vectors is not None:
            write_atomic(vectors, result.vectors_csv(), outputs)
            wrote.append(vectors)
        if regions is not None:
            write_atomic(regions, result.regions_csv(), outputs)
            wrote.append(regions)
        if regions_3d is not None:
            if result.consistency_3d is None:
                warnings.warn(f"{regions_3d}: no 3D consistency map (it needs two 3D clouds): "
                              "the header alone", stacklevel=1)
            write_atomic(regions_3d, result.regions_3d_csv(), outputs)
            wrote.append(regions_3d)
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

