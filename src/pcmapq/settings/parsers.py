"""The option table's readers and showers: an option's text as the setting it gives (refused
in one line naming the option, :class:`OptionError`), and a setting as the text that gives it."""

from __future__ import annotations

import math

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.features.names import DETECTOR_NAMES
from pcmapq.raster.rules import FOOTPRINT_RULES


class OptionError(InputError):
    """An option's value that cannot be read: one line, naming the option (exit 2)."""

    def __init__(self, message: str, option: str) -> None:
        super().__init__(message)
        self.message, self.option = message, option


def parse_init(text: str) -> Similarity2D:
    """``x,y,yaw`` (metres, metres, degrees; finite) as a map -> truth guess."""
    try:
        x, y, yaw = (float(v) for v in text.split(","))
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(text)
    except ValueError:
        raise OptionError(f"expected finite x,y,yaw (metres, metres, degrees), got {text!r}",
                          "--init") from None
    return Similarity2D(x, y, float(np.radians(yaw)))


def show_init(tf: Similarity2D | None) -> str | None:
    return None if tf is None else f"{tf.tx:g},{tf.ty:g},{np.degrees(tf.yaw):g}"


def parse_box(text: str, option: str) -> tuple[float, float, float, float]:
    """A box ``x0,y0,x1,y1`` (metres, finite, x0 < x1, y0 < y1)."""
    try:
        x0, y0, x1, y1 = (float(v) for v in text.split(","))
        if not (all(math.isfinite(v) for v in (x0, y0, x1, y1)) and x0 < x1 and y0 < y1):
            raise ValueError(text)
    except ValueError:
        raise OptionError(f"expected a box x0,y0,x1,y1 in metres with x0 < x1 and y0 < y1, got "
                          f"{text!r}", option) from None
    return x0, y0, x1, y1


def show_list(values: tuple | None) -> str | None:
    return None if values is None else ",".join(f"{v:g}" if isinstance(v, float) else str(v)
                                                for v in values)


def parse_map_resolution(text: str) -> float | None:
    """Metres per pixel, or ``auto`` (None: the scale is estimated)."""
    if text == "auto":
        return None
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 < value < math.inf:
        raise OptionError(f"expected metres per pixel or 'auto', got {text!r}",
                          "--map-resolution")
    return value


def parse_scale(text: str) -> bool:
    if text not in ("fixed", "auto"):
        raise OptionError(f"expected 'fixed' or 'auto', got {text!r}", "--scale")
    return text == "auto"


def parse_taus(text: str) -> tuple[float, ...]:
    """Positive finite distances, metres, comma-separated."""
    try:
        taus = tuple(float(v) for v in text.split(","))
    except ValueError:
        taus = ()
    if not taus or not all(0 < t < math.inf for t in taus):
        raise OptionError(f"expected positive finite distances in metres, got {text!r}",
                          "--tau")
    return taus


def parse_detectors(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    unknown = [n for n in names if n not in DETECTOR_NAMES]
    if unknown or not names:
        raise OptionError(f"unknown detector(s) {unknown}; choose from "
                          f"{','.join(DETECTOR_NAMES)}", "--detectors")
    return names


def parse_footprint(text: str) -> str:
    if text not in FOOTPRINT_RULES:
        raise OptionError(f"expected one of {', '.join(FOOTPRINT_RULES)}, got {text!r}",
                          "--footprint")
    return text
