"""ROS map_server YAML: the metadata of an occupancy image (resolution, origin, thresholds,
negate, mode), read and checked with map_server's rules, and the overrides the command line
gives (:class:`Thresholds`)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TypeVar

import yaml

from pcmapq.core.errors import InputError
from pcmapq.io.writers import one_line

MODES = ("trinary", "scale", "raw")
_T = TypeVar("_T")
#: A decimal number as text, exponent allowed: ``5e-2``, ``1.0e9``, ``-.5``. PyYAML (YAML 1.1)
#: reads an exponent without a dot or a signed exponent as a string; map_server reads a number.
_NUMBER_TEXT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


@dataclass(frozen=True)
class MapMeta:
    """The map_server YAML fields that matter here. Thresholds are probabilities in [0, 1]."""

    resolution: float | None
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    negate: bool = False
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    mode: str = "trinary"


@dataclass(frozen=True)
class Thresholds:
    """map_server reading options given on the command line; each one that is not None
    overrides the YAML's value (or map_server's default when there is no YAML).
    occupied, free: probabilities in [0, 1]; negate: read dark as free."""

    occupied: float | None = None
    free: float | None = None
    negate: bool | None = None

    def apply(self, meta: MapMeta) -> MapMeta:
        """``meta`` with these overrides."""
        return replace(meta,
                       occupied_thresh=_pick(self.occupied, meta.occupied_thresh),
                       free_thresh=_pick(self.free, meta.free_thresh),
                       negate=_pick(self.negate, meta.negate))


def _pick(value: _T | None, default: _T) -> _T:
    """``value`` unless it is None."""
    return default if value is None else value


def as_written(named: Path, yaml_path: Path) -> Path:
    """The image a YAML names, as its ``image`` key gives it (relative to the YAML's folder)."""
    try:
        return named.relative_to(yaml_path.parent)
    except ValueError:
        return named


def is_map_yaml(path: Path) -> bool:
    """Whether ``path`` is YAML naming an image, as every map_server YAML does."""
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return False
    return isinstance(doc, dict) and "image" in doc


def after_path(error: InputError) -> str:
    """An InputError's message without its leading ``path: ``."""
    return str(error).split(": ", 1)[-1]


def read_yaml(path: Path) -> tuple[MapMeta, Path]:
    """Parse and check a map_server YAML: its metadata and the path of the image it names
    (relative to the YAML's folder; not checked here)."""
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise InputError(f"{path}: cannot be read as YAML: {_yaml_problem(exc)}") from None
    if not isinstance(doc, dict):
        raise InputError(f"{path}: not a map_server YAML (expected a mapping of keys)")
    for key in ("image", "resolution", "origin"):
        if key not in doc:
            raise InputError(f"{path}: no '{key}' key")
    if not isinstance(doc["image"], str) or not doc["image"]:
        raise InputError(f"{path}: 'image' must be a file name")
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        raise InputError(f"{path}: unknown mode {mode!r} (expected one of {', '.join(MODES)})")
    meta = MapMeta(
        resolution=resolution_of(path, doc["resolution"]),
        origin=_origin(path, doc["origin"]),
        negate=_flag(path, "negate", doc.get("negate", 0)),
        occupied_thresh=_probability(path, "occupied_thresh", doc.get("occupied_thresh", 0.65)),
        free_thresh=_probability(path, "free_thresh", doc.get("free_thresh", 0.196)),
        mode=mode,
    )
    return meta, path.parent / doc["image"]


def _yaml_problem(exc: Exception) -> str:
    """One line for a YAML read error: the parser's problem and line, or the OS error."""
    if isinstance(exc, yaml.MarkedYAMLError) and exc.problem and exc.problem_mark:
        return f"{exc.problem} (line {exc.problem_mark.line + 1})"
    return one_line(exc)


def _number(path: Path, key: str, value: object) -> float:
    """A YAML value that must be a finite number: a YAML number, or text that reads as one
    (``5e-2``, ``1.0e9``), as map_server accepts."""
    if isinstance(value, str) and _NUMBER_TEXT.fullmatch(value.strip()):
        value = float(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{path}: '{key}' must be a finite number, got {value!r}")
    return float(value)


def _flag(path: Path, key: str, value: object) -> bool:
    """A YAML yes/no: a boolean or a number (non-zero is true)."""
    return value if isinstance(value, bool) else _number(path, key, value) != 0.0


def resolution_of(path: Path, value: object) -> float:
    """A cell size in metres: a positive finite number."""
    res = _number(path, "resolution", value)
    if res <= 0:
        raise InputError(f"{path}: 'resolution' must be positive, got {value!r}")
    return res


def _probability(path: Path, key: str, value: object) -> float:
    """A threshold in [0, 1]."""
    p = _number(path, key, value)
    if not 0.0 <= p <= 1.0:
        raise InputError(f"{path}: '{key}' must be between 0 and 1, got {value!r}")
    return p


def _origin(path: Path, value: object) -> tuple[float, float, float]:
    """``[x, y]`` or ``[x, y, yaw]`` (metres, metres, radians) -> (x, y, yaw)."""
    if not isinstance(value, (list, tuple)) or len(value) not in (2, 3):
        raise InputError(f"{path}: 'origin' must be a list [x, y, yaw], got {value!r}")
    xyz = [_number(path, "origin", v) for v in value]
    return xyz[0], xyz[1], xyz[2] if len(xyz) == 3 else 0.0
