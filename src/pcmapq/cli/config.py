"""``pcmapq config``: the settings as YAML on stdout, for ``--config``."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer
import yaml
from rich.console import Console

from pcmapq.cli.commands import HELP, app
from pcmapq.cli.terminal import report_errors
from pcmapq.core.words import count
from pcmapq.settings.build import base_settings
from pcmapq.settings.file import changed_settings, dump_settings, read_settings


@app.command("config", help=HELP["config"])
def config_command(
    dump: Annotated[bool, typer.Option(
        "--dump", help="Print every setting with its value as YAML: "
        "pcmapq config --dump > settings.yaml.")] = False,
    config: Annotated[Path | None, typer.Option(
        metavar="FILE", help="A settings file: check it and print the settings it changes as "
        "read (with --dump: every setting, the file's over the defaults).")] = None,
) -> None:
    err = Console(stderr=True)
    with report_errors(err):
        if not dump and config is None:
            raise typer.BadParameter("give --dump (pcmapq config --dump > settings.yaml) or "
                                     "--config FILE (a check of the file)",
                                     param_hint="--dump")
        base = settings = base_settings("eval")
        if config is not None:
            settings = read_settings(config, settings)
    if dump:
        sys.stdout.write(dump_settings(settings))
        return
    assert config is not None
    sys.stdout.write(checked_file(config, changed_settings(settings, base)))


def checked_file(path: Path, changed: dict) -> str:
    """What ``config --config FILE`` prints of a file read without error: a comment line
    naming it, then the settings it changes from the defaults as YAML."""
    if not changed:
        return f"# {path}: read; every setting at its default\n"
    n = count_settings(changed)
    return (f"# {path}: read; {count(n, 'setting')} changed from the defaults\n"
            + yaml.safe_dump(changed, sort_keys=False))


def count_settings(doc: dict) -> int:
    """The number of settings (leaves) in a nested settings document."""
    return sum(count_settings(v) if isinstance(v, dict) else 1 for v in doc.values())
