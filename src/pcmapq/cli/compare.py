"""``pcmapq compare``: saved results side by side."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from pcmapq.cli import terminal
from pcmapq.cli.commands import HELP, app
from pcmapq.cli.terminal import (
    report_errors,
)


@app.command("compare", help=HELP["compare"])
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
    from pcmapq.report.summary import print_summary, write_summary
    from pcmapq.results.compare import check_same_settings, check_same_truth, read_results

    err = Console(stderr=True)
    with report_errors(err), terminal.show_warnings(err):
        saved = read_results(results, None if names is None else names.split(","))
        for line in (check_same_truth(saved, allow_different_truths),
                     check_same_settings(saved)):
            if line is not None:
                warnings.warn(line, stacklevel=1)
        rows = [s.row for s in saved]
        wrote = write_summary(rows, out)
    if not quiet:
        for path in wrote:  # as the user wrote --out, as eval's and batch's
            err.print(f"wrote {out / path.name}", markup=False, highlight=False,
                      soft_wrap=True)
        print_summary(rows, Console())

