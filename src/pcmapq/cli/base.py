"""What the ``pcmapq`` command line is before its commands are imported: the Typer
application with its global options, and each command's help. Light on purpose: ``pcmapq
--help`` and ``--version`` are answered from here (:func:`pcmapq.cli.main`) without loading
the pipeline (Open3D, KISS-ICP, OpenCV), which takes seconds."""

from __future__ import annotations

from typing import Annotated

import typer

from pcmapq import __version__
from pcmapq.cli.terminal import HELP_WIDTH, OneLineUsageErrors

#: Each command's help, by name, in the order ``pcmapq --help`` lists them.
HELP = {
    "eval": "Align MAP to TRUTH, then score it with Harris, Hough, SIFT and room features.",
    "map": "Build a map from LiDAR scans with KISS-ICP (or with given poses) and save it.",
    "inspect": "How good is a map without a ground truth: MME, MPV and MOM of a 3D cloud, "
               "occupancy figures of a 2D map (docs/metrics.md).",
    "compare": "Compare saved results side by side (like evo_res): a table and a figure of "
               "the qualities, precisions, f1, coverage, alignment and wall distances (metres, "
               "degrees).",
    "batch": "Evaluate many maps, on local processes or a Dask cluster: a result per row, a "
             "table and a figure of them all; a rerun skips the rows already done. Exit 1 if "
             "any row failed, else 3 if a row failed a gate.",
    "track": "Score a SLAM run's map as it grows, every N scans or D metres, against the "
             "truth: when did the map go wrong, and where was the robot then?",
    "info": "What pcmapq sees in an input: a recording's topics, types, counts and time span; "
            "a cloud's points, bounds and fields; an image's size, resolution, thresholds and "
            "occupied share.",
    "config": "Write the settings (every option of eval, batch, track and inspect) as a YAML "
              "file to pass to --config.",
}


def _print_version(value: bool) -> None:
    """--version: print pcmapq's version and stop."""
    if value:
        print(f"pcmapq {__version__}")
        raise typer.Exit()


def new_app() -> typer.Typer:
    """The application with its global options and no command. Help at the terminal's width
    (click caps it at 80 columns unless told otherwise), as plain text: rich's markup would
    eat "[default: ...]" and squeeze the help into a narrow column."""
    app = typer.Typer(cls=OneLineUsageErrors, add_completion=False, no_args_is_help=True,
                      pretty_exceptions_enable=False, rich_markup_mode=None,
                      context_settings={"max_content_width": HELP_WIDTH},
                      help="Map quality against a ground-truth map, in metres.")

    @app.callback()
    def main(
        version: Annotated[bool, typer.Option(
            "--version", help="Print pcmapq's version and exit.", callback=_print_version,
            is_eager=True)] = False,
    ) -> None:
        """pcmapq: score a robot-made map against a ground-truth map (frame convention:
        p_truth = s * R(yaw) * p_map + t; metres and degrees). The scores are defined in
        docs/metrics.md."""

    return app


def listing_app() -> typer.Typer:
    """The application with every command's name and help but none of its options: what
    ``pcmapq --help`` shows, without importing the commands."""
    app = new_app()
    for name, text in HELP.items():
        app.command(name, help=text)(lambda: None)
    return app
