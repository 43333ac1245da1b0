"""The ``pcmapq`` Typer application, its global options and what every command shares."""

from __future__ import annotations

from typing import Annotated

import typer

from pcmapq import __version__, options
from pcmapq.config import Settings
from pcmapq.terminal import HELP_WIDTH, OneLineUsageErrors

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
#: The memory limit of eval and track, in GB (:func:`memory_limit` in bytes).
MaxMemory = Annotated[float | None, typer.Option(
    help="Stop (exit 2) before a run estimated to need more than this many GB "
    "(default: 75 % of this machine's memory).", min=0.0, show_default=False,
    callback=options.finite)]


def memory_limit(max_memory: float | None) -> int | None:
    """``--max-memory`` GB in bytes; None (the default limit) without it."""
    return None if max_memory is None else int(max_memory * 1e9)
