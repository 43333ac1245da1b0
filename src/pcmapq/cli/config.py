"""``pcmapq config``: the settings as YAML on stdout, for ``--config``."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from pcmapq.cli.commands import HELP, app
from pcmapq.cli.terminal import report_errors
from pcmapq.settings.build import base_settings
from pcmapq.settings.file import dump_settings, read_settings


@app.command("config", help=HELP["config"])
def config_command(
    dump: Annotated[bool, typer.Option(
        "--dump", help="Print every setting with its value as YAML: "
        "pcmapq config --dump > settings.yaml.")] = False,
    config: Annotated[Path | None, typer.Option(
        metavar="FILE", help="A settings file: print its settings over the defaults (a check "
        "of the file).")] = None,
) -> None:
    err = Console(stderr=True)
    with report_errors(err):
        if not dump:
            raise typer.BadParameter("give --dump (pcmapq config --dump > settings.yaml)",
                                     param_hint="--dump")
        settings = base_settings("eval")
        if config is not None:
            settings = read_settings(config, settings)
    sys.stdout.write(dump_settings(settings))
