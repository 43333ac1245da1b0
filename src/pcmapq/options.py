"""The command line's option text turned into typed values (typer.BadParameter on bad text),
and the command line rebuilt from its parsed options."""

from __future__ import annotations

import shlex

import numpy as np
import typer

from pcmapq.config import DETECTOR_NAMES
from pcmapq.io import Thresholds
from pcmapq.raster.footprint import FOOTPRINT_RULES
from pcmapq.transform import Similarity2D


def command_line(ctx: typer.Context) -> str:
    """The command as given, rebuilt from its parsed parameters (defaults left out), so a saved
    result says how it was made: ``pcmapq eval MAP TRUTH --option value ...``."""
    words = ["pcmapq", ctx.info_name or "eval"]
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        source = ctx.get_parameter_source(param.name)
        if source is None or source.name == "DEFAULT" or value is None:
            continue
        if param.param_type_name == "argument":
            words += [str(v) for v in (value if isinstance(value, (list, tuple)) else [value])]
        elif isinstance(value, bool) and param.is_flag:
            if value or param.secondary_opts:
                words.append(param.opts[0] if value else param.secondary_opts[0])
        else:
            words += [param.opts[0], str(value)]
    return shlex.join(words)


def parse_init(text: str | None) -> Similarity2D | None:
    if text is None:
        return None
    try:
        x, y, yaw = (float(v) for v in text.split(","))
    except ValueError:
        raise typer.BadParameter(f"expected x,y,yaw (metres, metres, degrees), got {text!r}",
                                 param_hint="--init") from None
    return Similarity2D(x, y, float(np.radians(yaw)))


def parse_resolution(text: str | None, scale: str) -> tuple[float | None, bool]:
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


def thresholds(occupied: float | None, free: float | None,
                negate: bool | None) -> Thresholds | None:
    """map_server overrides from the command line (None when none is given)."""
    if occupied is None and free is None and negate is None:
        return None
    return Thresholds(occupied, free, negate)


def parse_taus(text: str) -> tuple[float, ...]:
    try:
        taus = tuple(float(v) for v in text.split(","))
    except ValueError:
        taus = ()
    if not taus or min(taus) <= 0:
        raise typer.BadParameter(f"expected positive distances in metres, got {text!r}",
                                 param_hint="--tau")
    return taus


def parse_detectors(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    unknown = [n for n in names if n not in DETECTOR_NAMES]
    if unknown or not names:
        raise typer.BadParameter(f"unknown detector(s) {unknown}; choose from "
                                 f"{','.join(DETECTOR_NAMES)}", param_hint="--detectors")
    return names


def parse_footprint(text: str) -> str:
    if text not in FOOTPRINT_RULES:
        raise typer.BadParameter(f"expected one of {', '.join(FOOTPRINT_RULES)}, got {text!r}",
                                 param_hint="--footprint")
    return text
