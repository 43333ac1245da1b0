"""The ``pcmapq`` Typer application (:mod:`pcmapq.cli.base`) that the commands register on, and
what they share: the CI gates, the memory limit."""

from __future__ import annotations

from typing import Annotated

import typer

from pcmapq.cli import options
from pcmapq.cli.base import HELP, new_app
from pcmapq.core.memory import DEFAULT_SHARE

app = new_app()
__all__ = ["HELP", "app"]


#: The CI gates of eval (one result) and batch (every row; docs/ci.md).
FailUnder = Annotated[str | None, typer.Option(
    metavar="<KEY=VALUE,...>",
    help="CI gate: exit 3 when a figure is below its bound, e.g. "
    "harris.quality=0.8,coverage=0.9 (keys: docs/ci.md; a figure that is n/a fails). The "
    "outputs are written all the same.")]
FailOver = Annotated[str | None, typer.Option(
    metavar="<KEY=VALUE,...>",
    help="CI gate for distances: exit 3 when a figure is above its bound, e.g. "
    "accuracy.mean=0.05 (metres).")]
RowsFailUnder = Annotated[str | None, typer.Option(
    "--fail-under", metavar="<KEY=VALUE,...>",
    help="CI gate: exit 3 when a figure of any row is below its bound, e.g. "
    "harris.quality=0.8,coverage=0.9 (keys: docs/ci.md; a figure that is n/a fails). The "
    "outputs are written all the same.")]
RowsFailOver = Annotated[str | None, typer.Option(
    "--fail-over", metavar="<KEY=VALUE,...>",
    help="CI gate for distances: exit 3 when a figure of any row is above its bound, e.g. "
    "accuracy.mean=0.05 (metres).")]
#: A recording's scan topic (eval's --scans, map and track) and the tf frame of its scans'
#: poses (map and track).
ScanTopic = Annotated[str | None, typer.Option(
    help="A recording's PointCloud2 or LaserScan topic (default: the only one).")]
TfFrame = Annotated[str | None, typer.Option(
    "--frame", help="With --pose-topic /tf: the frame whose poses place the scans (default: "
    "the scans' own frame), in the transform tree's root frame.")]
#: The memory limit of eval and track, in GB (:func:`memory_limit` in bytes).
MaxMemory = Annotated[float | None, typer.Option(
    help="Stop (exit 2) before a run estimated to need more than this many GB "
    f"(default: {DEFAULT_SHARE * 100:g} % of this machine's memory).", min=0.0, show_default=False,
    callback=options.finite)]


def memory_limit(max_memory: float | None) -> int | None:
    """``--max-memory`` GB in bytes; None (the default limit) without it."""
    return None if max_memory is None else int(max_memory * 1e9)
