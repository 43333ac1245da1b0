"""The command line: parse options, call the pipeline, show and save the result. No logic."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console

from pcmapq.align.transform import Similarity2D
from pcmapq.config import DETECTOR_NAMES, Settings
from pcmapq.errors import EvaluationError, InputError
from pcmapq.io.writers import write_atomic
from pcmapq.metrics.distances import DEFAULT_TAUS
from pcmapq.pipeline import evaluate
from pcmapq.report.table import print_table

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Map quality against a ground-truth map, in metres.")


@app.callback()
def main() -> None:
    """pcmapq: score a robot-made map against a ground-truth map (frame convention:
    p_truth = s * R(yaw) * p_map + t; metres and degrees)."""


@contextmanager
def _progress(console: Console, enabled: bool) -> Iterator[Callable[[str], None]]:
    """A spinner on the terminal naming the current step; nothing when not a terminal."""
    if not (enabled and console.is_terminal):
        yield lambda step: None
        return
    with console.status("pcmapq") as status:
        yield lambda step: status.update(f"{step}...")


def _parse_init(text: str | None) -> Similarity2D | None:
    if text is None:
        return None
    try:
        x, y, yaw = (float(v) for v in text.split(","))
    except ValueError:
        raise typer.BadParameter(f"expected x,y,yaw (metres, metres, degrees), got {text!r}",
                                 param_hint="--init") from None
    return Similarity2D(x, y, float(np.radians(yaw)))


def _parse_resolution(text: str | None, scale: str) -> tuple[float | None, bool]:
    """(--map-resolution as metres or None, whether to estimate the scale)."""
    if scale not in ("fixed", "auto"):
        raise typer.BadParameter(f"expected 'fixed' or 'auto', got {scale!r}", param_hint="--scale")
    if text is None or text == "auto":
        return None, scale == "auto" or text == "auto"
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0:
        raise typer.BadParameter(f"expected metres per pixel or 'auto', got {text!r}",
                                 param_hint="--map-resolution")
    return value, scale == "auto"


def _parse_taus(text: str) -> tuple[float, ...]:
    try:
        taus = tuple(float(v) for v in text.split(","))
    except ValueError:
        taus = ()
    if not taus or min(taus) <= 0:
        raise typer.BadParameter(f"expected positive distances in metres, got {text!r}",
                                 param_hint="--tau")
    return taus


def _parse_detectors(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    unknown = [n for n in names if n not in DETECTOR_NAMES]
    if unknown or not names:
        raise typer.BadParameter(f"unknown detector(s) {unknown}; choose from "
                                 f"{','.join(DETECTOR_NAMES)}", param_hint="--detectors")
    return names


@app.command("eval")
def eval_command(
    map_path: Annotated[Path, typer.Argument(metavar="MAP", help="Map to score: image (.png/.pgm, "
                        "with its ROS YAML), YAML, or cloud (.ply/.pcd/.xyz/.npy/.bin).")],
    truth_path: Annotated[Path, typer.Argument(metavar="TRUTH", help="Ground truth, same kinds.")],
    map_resolution: Annotated[str | None, typer.Option(
        help="Metres per pixel of a map image without YAML (overrides its YAML); 'auto' "
        "estimates the map's scale (same as --scale auto).")] = None,
    scale: Annotated[str, typer.Option(
        help="'fixed': the map's metres are metres; 'auto': estimate its scale too (a "
        "similarity), for maps whose resolution is unknown.")] = "fixed",
    truth_resolution: Annotated[float | None, typer.Option(
        help="Metres per pixel of a truth image without YAML; cell size for a cloud truth "
        "(default 0.05).", min=1e-6)] = None,
    init: Annotated[str | None, typer.Option(
        help="Initial guess x,y,yaw (m, m, deg), map -> truth; skips the global search.")] = None,
    no_align: Annotated[bool, typer.Option(
        "--no-align", help="Trust the map's frame: no alignment at all.")] = False,
    force: Annotated[bool, typer.Option(
        help="Evaluate even when the map does not seem to show the truth's place.")] = False,
    threshold: Annotated[float, typer.Option(
        help="Largest distance between matched features, metres.", min=1e-6)] = 0.5,
    band_low: Annotated[float, typer.Option(
        help="Wall band of a 3D cloud: lower bound, metres above the floor.")] = 0.3,
    band_high: Annotated[float, typer.Option(
        help="Wall band of a 3D cloud: upper bound, metres above the floor.")] = 2.0,
    min_hits: Annotated[int | None, typer.Option(
        help="Points needed to mark a cloud's cell occupied [default: 2 for a 3D cloud, 1 for "
        "a 2D one].", min=1, show_default=False)] = None,
    detectors: Annotated[str, typer.Option(
        help="Comma-separated detectors to run.")] = ",".join(DETECTOR_NAMES),
    json_path: Annotated[str | None, typer.Option(
        "--json", help="Write the result as JSON to this path ('-' for stdout only).")] = None,
    vectors: Annotated[Path | None, typer.Option(
        help="Write the matched displacements (the vectorial map) as CSV.")] = None,
    plot: Annotated[Path | None, typer.Option(
        help="Draw the vectorial map, one panel per detector, as PNG.")] = None,
    report: Annotated[Path | None, typer.Option(
        help="Write a self-contained HTML report (figures embedded).")] = None,
    tau: Annotated[str, typer.Option(
        help="Distance thresholds of the F-score, metres, comma-separated.")
    ] = ",".join(f"{t:g}" for t in DEFAULT_TAUS),
    full: Annotated[bool, typer.Option(
        "--full", help="Score against the whole truth, not only the part the map covers.")
    ] = False,
) -> None:
    """Align MAP to TRUTH, then score it with Harris, Hough and SIFT features."""
    resolution, auto = _parse_resolution(map_resolution, scale)
    settings = Settings(map_resolution=resolution, truth_resolution=truth_resolution,
                        scale=auto,
                        band_low=band_low, band_high=band_high, init=_parse_init(init),
                        align=not no_align, force=force, threshold=threshold, min_hits=min_hits,
                        detectors=_parse_detectors(detectors), full=full, taus=_parse_taus(tau))
    quiet = json_path == "-"
    err = Console(stderr=True)
    out = Console(quiet=quiet, width=None if err.is_terminal else 132)
    try:
        with _progress(err, enabled=not quiet) as progress:
            result = evaluate(map_path, truth_path, settings, progress)
            progress("writing outputs")
            if json_path == "-":
                sys.stdout.write(result.to_json())
            elif json_path is not None:
                write_atomic(Path(json_path), result.to_json())
            if vectors is not None:
                write_atomic(vectors, result.vectors_csv())
            if plot is not None or report is not None:
                from pcmapq.report.html import report_html
                from pcmapq.report.plot import png_bytes, vectorial_figure
            if plot is not None:
                write_atomic(plot, png_bytes(vectorial_figure(result)))
            if report is not None:
                write_atomic(report, report_html(result))
    except (InputError, EvaluationError) as error:
        err.print(f"pcmapq: error: {error}", markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(error.exit_code) from None
    print_table(result, out)
