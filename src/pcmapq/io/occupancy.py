"""Occupancy images and ROS map_server YAML, read with exactly map_server's semantics.

A pixel's grey value ``v`` (colour: mean of the colour channels; 16-bit images scaled to 0..255)
gives ``p = (255 - v) / 255`` (``v / 255`` when ``negate``); the cell is occupied if
``p > occupied_thresh``, free if ``p < free_thresh`` and unknown otherwise. A transparent pixel
(alpha 0) is unknown. The grid's frame is the map_server one: ``origin`` is the pose of the
image's lower-left corner (see :mod:`pcmapq.core.grid`). One reading goes beyond map_server's: the
outside of a building drawn solid, reaching the image's border, is read as its face
(:func:`open_outside`), as a laser sees it.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TypeVar

import cv2
import numpy as np
import yaml

from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import disc, outline, reaching_border
from pcmapq.io.image_header import check_image_size
from pcmapq.io.stderr import stderr_captured, stderr_uncaptured
from pcmapq.io.writers import one_line, same_file

IMAGE_SUFFIXES = (".png", ".pgm", ".jpg", ".jpeg", ".bmp")
YAML_SUFFIXES = (".yaml", ".yml")
MODES = ("trinary", "scale", "raw")
#: The problem of an image read without a resolution.
NO_RESOLUTION = "no resolution"
#: The outside of a building drawn solid is read as a wall this thick along its face, metres
#: (:func:`open_outside`): a plan's usual wall, whose centre line then lies where a plan drawn
#: with walls would put it, about half this beyond the face a laser sees.
FACE_M = 0.15
#: Parts of such a region thinner than this, metres, are walls or furniture joined to it, and
#: kept (the building's own thickest wall, :data:`pcmapq.features.walls.THICKEST`).
OUTSIDE_M = 2.0
_T = TypeVar("_T")
#: A decimal number as text, exponent allowed: ``5e-2``, ``1.0e9``, ``-.5``. PyYAML (YAML 1.1)
#: reads an exponent without a dot or a signed exponent as a string; map_server reads a number.
_NUMBER_TEXT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


@dataclass(frozen=True)
class OccupancyMap:
    """An occupancy image with its metric frame.

    path: the file given (image or YAML).
    grid: cell size and pose of the image in the map's metric frame.
    state: (rows, cols) int8, OCCUPIED (1), FREE (0) or UNKNOWN (-1); row 0 is the image's top.
    empty: why no cell is occupied, and what would read its walls (empty when some are).
    """

    path: Path
    grid: MetricGrid
    state: np.ndarray
    kind: str = "image"
    empty: str = ""


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


def load_occupancy(path: Path, resolution: float | None = None,
                   fallback: float | None = None,
                   thresholds: Thresholds | None = None,
                   memory_limit: int | None = None) -> OccupancyMap:
    """Load an occupancy image or a map_server YAML. ``resolution`` (metres per cell), if given,
    overrides the YAML's; an image without a YAML beside it (same stem) needs it, or a
    ``fallback`` resolution (a starting guess for a map whose scale will be estimated).
    ``thresholds`` override the YAML's occupied_thresh, free_thresh and negate; an image whose
    header declares more pixels than ``memory_limit`` bytes hold (None: the default) is refused
    unread."""
    if path.suffix.lower() in YAML_SUFFIXES:
        meta, image = read_yaml(path)
        if not image.is_file():
            raise InputError(f"{path}: image '{image.name}' not found")
    else:
        image = path
        meta = _meta_beside(path, resolution)
    if resolution is not None:
        meta = replace(meta, resolution=_resolution(path, resolution))
    if thresholds is not None:
        meta = thresholds.apply(meta)
    levels, channels, scale, transparent = read_levels(image, memory_limit)
    if meta.resolution is None and fallback is not None:
        meta = replace(meta, resolution=_resolution(path, fallback))
    if meta.resolution is None:
        raise InputError(f"{path}: {NO_RESOLUTION}: give --map-resolution/--truth-resolution "
                         "or a YAML beside it")
    state = classify(levels, channels, scale, transparent, meta)
    empty = "" if (state == OCCUPIED).any() else _darkest(levels, channels, scale, transparent,
                                                          meta)
    state = open_outside(state, meta.resolution)
    return OccupancyMap(path, MetricGrid(meta.resolution, meta.origin, state.shape), state,
                        empty=empty)


def _darkest(levels: np.ndarray, channels: int, scale: float, transparent: np.ndarray,
             meta: MapMeta) -> str:
    """Why an image has no occupied cell and what to change, one clause: its most occupied
    pixel's p against ``occupied_thresh`` (walls drawn grey, as a CARMEN map's are)."""
    shown = levels[~transparent]
    if shown.size == 0:
        return "every pixel is transparent"
    value = np.unique(shown) / channels * scale
    p = occupancy_of(value, meta)
    if meta.mode == "raw":
        p = p[value <= 100.0]
    top = float(p.max(initial=0.0))
    return (f"its darkest pixels read p = {top:.2f}, not above occupied_thresh "
            f"{meta.occupied_thresh:g}; walls drawn grey need a lower --map-occupied-thresh "
            "or --truth-occupied-thresh (occupied_thresh in its YAML)")


def open_outside(state: np.ndarray, resolution: float) -> np.ndarray:
    """``state`` (int8 cells) with the outside of a building drawn solid read as its face: in
    occupied regions that reach the image's border, the cells of parts thicker than
    OUTSIDE_M (an opening by a disc of half that) and deeper than FACE_M metres inside the
    region are UNKNOWN. The image goes on beyond its border as it is there, so a wall drawn
    along the border keeps every cell, and so do walls and furniture joined to the border (none
    that thick) and a region with no face (an all-black image). The state itself when no
    border cell is occupied."""
    occupied = state == OCCUPIED
    if not (occupied[0].any() or occupied[-1].any() or occupied[:, 0].any()
            or occupied[:, -1].any()):
        return state
    outside = reaching_border(occupied).view(np.uint8)
    thick = cv2.morphologyEx(outside, cv2.MORPH_OPEN, disc(0.5 * OUTSIDE_M / resolution),
                             borderType=cv2.BORDER_REPLICATE)
    face = outline(outside.view(bool), FACE_M / resolution, edge_is_outside=False)
    if not face.any():
        return state
    deep = thick.view(bool) & ~face
    if not deep.any():
        return state
    return np.where(deep, np.int8(UNKNOWN), state).astype(np.int8)


def _meta_beside(image: Path, resolution: float | None) -> MapMeta:
    """The map_server metadata of the YAML beside an image (same stem), or none. A YAML there
    that is not a map_server file (no ``image`` key, or not YAML at all: a results file) is
    ignored with a warning when a ``resolution`` is given, and an error otherwise. A YAML that
    names another image is used all the same (the image given is read), with a warning."""
    beside = [image.with_suffix(s) for s in YAML_SUFFIXES if image.with_suffix(s).is_file()]
    if not beside:
        return MapMeta(resolution=None)
    try:
        meta, named = read_yaml(beside[0])
    except InputError as error:
        if resolution is None or _is_map_yaml(beside[0]):
            raise
        _warn(f"{beside[0]}: ignored, not a map_server YAML ({_after_path(error)}); "
              f"{image.name} read with the resolution given, {resolution:g} m")
        return MapMeta(resolution=None)
    if not same_file(image, named):
        used = "origin and thresholds" if resolution is not None else \
            "resolution, origin and thresholds"
        _warn(f"{beside[0]}: names image '{_as_written(named, beside[0])}', not {image.name}; "
              f"{image.name} read with this YAML's {used} (give the YAML itself to read the "
              "image it names)")
    return meta


def _warn(message: str) -> None:
    """A warning of :func:`_meta_beside`, from :func:`load_occupancy`'s line; shown while no
    other thread captures stderr (the truth is read while the map is), which would swallow it."""
    with stderr_uncaptured():
        warnings.warn(message, stacklevel=3)


def _as_written(named: Path, yaml_path: Path) -> Path:
    """The image a YAML names, as its ``image`` key gives it (relative to the YAML's folder)."""
    try:
        return named.relative_to(yaml_path.parent)
    except ValueError:
        return named


def _is_map_yaml(path: Path) -> bool:
    """Whether ``path`` is YAML naming an image, as every map_server YAML does."""
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return False
    return isinstance(doc, dict) and "image" in doc


def _after_path(error: InputError) -> str:
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
        resolution=_resolution(path, doc["resolution"]),
        origin=_origin(path, doc["origin"]),
        negate=_flag(path, "negate", doc.get("negate", 0)),
        occupied_thresh=_probability(path, "occupied_thresh", doc.get("occupied_thresh", 0.65)),
        free_thresh=_probability(path, "free_thresh", doc.get("free_thresh", 0.196)),
        mode=mode,
    )
    return meta, path.parent / doc["image"]


def read_levels(path: Path,
                memory_limit: int | None = None) -> tuple[np.ndarray, int, float, np.ndarray]:
    """An image's pixels as integer levels (rows, cols): the sum of its colour channels; the
    number of those channels, the grey value (0..255 scale) of one level of one channel, and
    a bool mask of transparent (alpha 0) pixels. A pixel's grey value is
    ``level / channels * scale``. The size its header declares is checked first, against
    ``memory_limit`` bytes (None: the default limit)."""
    check_image_size(path, memory_limit)
    try:
        with _opencv_quiet(), stderr_captured() as printed:
            img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    except cv2.error:
        img = None
    # libpng prints its errors (then OpenCV gives up, or keeps a partial image) and warnings
    # (about a sound image: dropped)
    errors = [line for line in printed if "error" in line.lower()]
    if img is None or img.size == 0 or errors:
        why = f": {errors[0].strip()}" if errors else ""
        raise InputError(f"{path}: cannot be read as an image{why}")
    if img.dtype not in (np.uint8, np.uint16):
        raise InputError(f"{path}: unsupported pixel type {img.dtype} (expected 8 or 16 bit)")
    scale = 255.0 / np.iinfo(img.dtype).max
    if img.ndim == 2:
        return img, 1, scale, np.zeros(img.shape, dtype=bool)
    channels = img.shape[2]
    has_alpha = channels in (2, 4)
    colour = img[:, :, : channels - 1] if has_alpha else img
    transparent = img[:, :, -1] == 0 if has_alpha else np.zeros(img.shape[:2], dtype=bool)
    return colour.sum(axis=2, dtype=np.int32), colour.shape[2], scale, transparent


@contextmanager
def _opencv_quiet() -> Iterator[None]:
    """OpenCV's log silenced in the block: a corrupt image is reported by ``imread`` returning
    nothing (an InputError here), not by OpenCV's ``[ERROR...]`` lines on stderr."""
    level = cv2.utils.logging.getLogLevel()
    cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)
    try:
        yield
    finally:
        cv2.utils.logging.setLogLevel(level)


def occupancy_of(value: np.ndarray, meta: MapMeta) -> np.ndarray:
    """map_server's occupancy probability p of grey values (0..255): ``(255 - v) / 255``,
    ``v / 255`` when ``negate``; in ``raw`` mode the value itself in percent."""
    if meta.mode == "raw":
        return value / 100.0
    return value / 255.0 if meta.negate else (255.0 - value) / 255.0


def classify(levels: np.ndarray, channels: int, scale: float, transparent: np.ndarray,
             meta: MapMeta) -> np.ndarray:
    """Cell states (int8 OCCUPIED/FREE/UNKNOWN) of :func:`read_levels`' pixels by map_server's
    rule, on their grey values ``level / channels * scale`` (0..255). ``raw`` mode reads the
    value itself as occupancy in percent (above 100: unknown) and ignores ``negate``. The rule
    is applied once per possible level, and the pixels look their state up."""
    value = np.arange(int(levels.max(initial=0)) + 1) / channels * scale
    p = occupancy_of(value, meta)
    state = np.full(value.shape, UNKNOWN, dtype=np.int8)
    state[p < meta.free_thresh] = FREE
    state[p > meta.occupied_thresh] = OCCUPIED
    if meta.mode == "raw":
        state[value > 100.0] = UNKNOWN
    state = state[levels]
    state[transparent] = UNKNOWN
    return state


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


def _resolution(path: Path, value: object) -> float:
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
