"""``pcmapq batch``: many maps, on local processes or a Dask cluster."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from pcmapq.cli import terminal
from pcmapq.cli.commands import HELP, RowsFailOver, RowsFailUnder, app
from pcmapq.cli.options import CONFIG_HELP
from pcmapq.cli.terminal import (
    report_errors,
)
from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.io import targets
from pcmapq.io.writers import OutputSet, same_file, write_atomic
from pcmapq.results import gates


@app.command("batch", help=HELP["batch"])
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
    config: Annotated[Path | None, typer.Option(
        metavar="FILE", help=CONFIG_HELP.replace("options given here", "a row's options and "
                                                 "--set"))] = None,
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
    fail_under: RowsFailUnder = None,
    fail_over: RowsFailOver = None,
    quiet: Annotated[bool, typer.Option(
        "--quiet", "-q", help="Print nothing but warnings and errors.")] = False,
) -> None:
    from pcmapq.batch import glob_rows, parse_assignments, read_rows, run_batch
    from pcmapq.batch.progress import row_bar

    err = Console(stderr=True)
    with report_errors(err), terminal.show_warnings(err):
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
            rows = glob_rows(sources, truth, defaults, config)
        elif len(sources) == 1:
            rows = read_rows(Path(sources[0]), defaults, config)
        else:
            raise typer.BadParameter("give one manifest, or maps with --truth",
                                     param_hint="MANIFEST | MAP...")
        if out.exists() and not out.is_dir():
            raise InputError(f"{out}: --out: not a folder")
        if json_path not in (None, "-"):
            out.mkdir(parents=True, exist_ok=True)  # --json may go into it
            targets.check_outputs({"--json": json_path}, None, inputs=())
            if any(same_file(Path(json_path), out / f"{r.name}.json") for r in rows):
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
        err.print(f"{count(len(outcomes), 'row')}: "
                  + ", ".join(f"{n} {s}" for s, n in counts.items())
                  + (f", {gated} failing a gate" if rules else "")
                  + f"; wrote {out / 'table.csv'}, table.md, figure.png", markup=False,
                  highlight=False, soft_wrap=True)
    if code:
        raise typer.Exit(code)

