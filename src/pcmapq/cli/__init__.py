"""The command line: parse options, call the pipeline, show and save the result. No logic.

One module per command (:mod:`~pcmapq.cli.evaluate`, :mod:`~pcmapq.cli.map_scans`,
:mod:`~pcmapq.cli.inspect`, :mod:`~pcmapq.cli.compare`, :mod:`~pcmapq.cli.batch`,
:mod:`~pcmapq.cli.track`, :mod:`~pcmapq.cli.info`, :mod:`~pcmapq.cli.config`), each
registering itself on :data:`~pcmapq.cli.commands.app`, which is imported on first use
(``from pcmapq.cli import app``): :func:`main`, the ``pcmapq`` command, answers ``--help`` and
``--version`` without it (:mod:`pcmapq.cli.base`).
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["app", "main"]

#: Arguments answered by :func:`~pcmapq.cli.base.listing_app` alone.
LISTING = ([], ["--help"], ["-h"], ["--version"])


def __getattr__(name: str) -> Any:
    if name == "app":
        # registered in the order of HELP, the order --help lists them in
        from pcmapq.cli import (  # noqa: F401, I001
            evaluate, map_scans, inspect, compare, batch, track, info, config)
        from pcmapq.cli.commands import app

        globals()["app"] = app
        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def main() -> None:
    """The ``pcmapq`` command: the whole application, or for ``pcmapq``, ``--help`` and
    ``--version`` the listing (the same output, in a fraction of the time)."""
    if sys.argv[1:] in LISTING:
        from pcmapq.cli.base import listing_app

        listing_app()()
    else:
        __getattr__("app")()
