"""The command line: parse options, call the pipeline, show and save the result. No logic.

One module per command (:data:`MODULES`: :mod:`~pcmapq.cli.evaluate`,
:mod:`~pcmapq.cli.map_scans`, :mod:`~pcmapq.cli.inspect`, :mod:`~pcmapq.cli.compare`,
:mod:`~pcmapq.cli.batch`, :mod:`~pcmapq.cli.track`, :mod:`~pcmapq.cli.info`,
:mod:`~pcmapq.cli.config`), each registering itself on :data:`~pcmapq.cli.commands.app`, which is
imported on first use (``from pcmapq.cli import app``). :func:`main`, the ``pcmapq`` command,
imports only what it runs: for ``--help`` and ``--version`` the listing
(:mod:`pcmapq.cli.base`), for one command that command's module alone.
"""

from __future__ import annotations

import gc
import importlib
import os
import sys
from typing import Any

from pcmapq.core.unused import leave_out_unused

__all__ = ["MODULES", "app", "main"]

#: Arguments answered by :func:`~pcmapq.cli.base.listing_app` alone.
LISTING = ([], ["--help"], ["-h"], ["--version"])
#: Threads of NumPy's and SciPy's OpenBLAS: pcmapq's linear algebra is on small systems (3 x 3
#: normal equations, batched 2 x 2 and 3 x 3 fits), where more threads only spin beside the
#: pipeline's own threads (docs/benchmarks.md). Set before NumPy loads; the user's value wins.
BLAS_THREADS = "1"
#: Each command's module in pcmapq.cli, in the order ``pcmapq --help`` lists them
#: (:data:`~pcmapq.cli.base.HELP`).
MODULES = {"eval": "evaluate", "map": "map_scans", "inspect": "inspect", "compare": "compare",
           "batch": "batch", "track": "track", "info": "info", "config": "config"}


def __getattr__(name: str) -> Any:
    if name == "app":
        for module in MODULES.values():  # registered in the order --help lists them
            importlib.import_module(f"{__name__}.{module}")
        from pcmapq.cli.commands import app

        globals()["app"] = app
        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def main() -> None:
    """The ``pcmapq`` command. ``pcmapq``, ``--help`` and ``--version``: the listing (the same
    output as the whole application); ``pcmapq COMMAND ...``: the application with that command
    alone, which parses, helps and fails as the whole one does (a command's start-up is then
    its own imports only); anything else: the whole application."""
    args = sys.argv[1:]
    os.environ.setdefault("OPENBLAS_NUM_THREADS", BLAS_THREADS)
    leave_out_unused()  # modules the command never uses (IPython, which Open3D's Dash loads)
    try:
        if args in LISTING:
            from pcmapq.cli.base import listing_app

            listing_app()()
        elif args[0] in MODULES:
            importlib.import_module(f"{__name__}.{MODULES[args[0]]}")
            from pcmapq.cli.commands import app

            app()
        else:
            __getattr__("app")()
    finally:
        # The command is over: the interpreter's exit need not search the objects of every
        # module it loaded for cycles (many, once Numba ran); they go with the process.
        gc.freeze()
