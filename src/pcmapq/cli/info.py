"""``pcmapq info``: what pcmapq sees in an input."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from pcmapq.cli.commands import HELP, MaxMemory, app, memory_limit
from pcmapq.cli.terminal import report_errors
from pcmapq.io import targets
from pcmapq.io.formats import map_formats
from pcmapq.io.writers import OutputSet, write_atomic


@app.command("info", help=HELP["info"])
def info_command(
    path: Annotated[Path, typer.Argument(
        metavar="FILE", help=f"Any input: {map_formats()}.")],
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Write the record as JSON to this path ('-' for stdout only).")] = None,
    max_memory: MaxMemory = None,
) -> None:
    from pcmapq.io.describe import describe, lines

    err = Console(stderr=True)
    json_path = targets.kept(json_path)
    with report_errors(err):
        targets.check_outputs({"--json": json_path}, None, inputs=(path,))
        record = describe(path, memory_limit(max_memory))
        text = json.dumps(record, indent=2) + "\n"
        if json_path not in (None, "-"):
            with OutputSet() as outputs:
                write_atomic(Path(json_path), text, outputs)
                outputs.commit()
    if json_path == "-":
        sys.stdout.write(text)
    else:
        print("\n".join(lines(record)))
