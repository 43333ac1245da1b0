"""Occupancy images read with exactly map_server's semantics (their YAML:
:mod:`pcmapq.io.map_yaml`).

A pixel's grey value ``v`` (colour: mean of the colour channels; 16-bit images scaled to 0..255)
gives ``p = (255 - v) / 255`` (``v / 255`` when ``negate``); the cell is occupied if
``p > occupied_thresh``, free if ``p < free_thresh`` and unknown otherwise. A transparent pixel
(alpha 0) is unknown. The grid's frame is the map_server one: ``origin`` is the pose of the
image's lower-left corner (see :mod:`pcmapq.core.grid`). The cells read are map_server's, on
every map (one documented departure: map_saver's unknown grey beside a Nav2 YAML whose
``free_thresh`` reads it as free, :func:`saver_unknown`). The evaluation reads one thing
further, on an image fine enough to draw it: the outside of a building drawn solid, reaching
the image's border, as its face (:func:`open_outside`), as a laser sees it.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import cv2
import numpy as np

from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import disc, outline, reaching_border
from pcmapq.io.formats import YAML_SUFFIXES
from pcmapq.io.image_header import check_image_size
from pcmapq.io.map_yaml import (
    MapMeta,
    Thresholds,
    after_path,
    as_written,
    is_map_yaml,
    read_yaml,
    resolution_of,
)
from pcmapq.io.stderr import stderr_captured, stderr_uncaptured
from pcmapq.io.writers import same_file

if TYPE_CHECKING:
    from pcmapq.io.bags import Message

#: The problem of an image read without a resolution.
NO_RESOLUTION = "no resolution"
#: The outside of a building drawn solid is read as a wall this thick along its face, metres
#: (:func:`open_outside`): a plan's usual wall, whose centre line then lies where a plan drawn
#: with walls would put it, about half this beyond the face a laser sees.
FACE_M = 0.15
#: The grey values map_saver writes in trinary mode: occupied, unknown, free.
SAVER_VALUES = (0, 205, 254)
SAVER_UNKNOWN = 205
#: Parts of such a region thinner than this, metres, are walls or furniture joined to it, and
#: kept (the building's own thickest wall, :data:`pcmapq.features.walls.THICKEST`).
OUTSIDE_M = 2.0


@dataclass(frozen=True)
class OccupancyMap:
    """An occupancy image with its metric frame.

    path: the file given (image or YAML).
    grid: cell size and pose of the image in the map's metric frame.
    state: (rows, cols) int8, OCCUPIED (1), FREE (0) or UNKNOWN (-1); row 0 is the image's top.
    empty: why no cell is occupied, and what would read its walls (empty when some are).
    message: the recording's message it was read from (None: a file).
    """

    path: Path
    grid: MetricGrid
    state: np.ndarray
    kind: str = "image"
    empty: str = ""
    message: Message | None = None


def load_occupancy(path: Path, resolution: float | None = None,
                   fallback: float | None = None,
                   thresholds: Thresholds | None = None,
                   memory_limit: int | None = None,
                   resolution_option: str = "--map-resolution") -> OccupancyMap:
    """Load an occupancy image or a map_server YAML. ``resolution`` (metres per cell), if given,
    overrides the YAML's; an image without a YAML beside it (same stem) needs it, or a
    ``fallback`` resolution (a starting guess for a map whose scale will be estimated); without
    either it is refused, naming ``resolution_option``. ``thresholds`` override the YAML's
    occupied_thresh, free_thresh and negate; an image whose header declares more pixels than
    ``memory_limit`` bytes hold (None: the default) is refused unread."""
    if path.suffix.lower() in YAML_SUFFIXES:
        meta, image = read_yaml(path)
        if not image.is_file():
            raise InputError(f"{path}: image '{image.name}' not found")
    else:
        image = path
        meta = _meta_beside(path, resolution)
    if resolution is not None:
        meta = replace(meta, resolution=resolution_of(path, resolution))
    if thresholds is not None:
        meta = thresholds.apply(meta)
    levels, channels, scale, transparent = read_levels(image, memory_limit)
    if meta.resolution is None and fallback is not None:
        meta = replace(meta, resolution=resolution_of(path, fallback))
    if meta.resolution is None:
        raise InputError(f"{path}: {NO_RESOLUTION}: give {resolution_option} or a YAML beside "
                         "it")
    state = classify(levels, channels, scale, transparent, meta)
    if thresholds is None or thresholds.free is None:
        state = saver_unknown(state, levels, channels, scale, meta, path)
    empty = "" if (state == OCCUPIED).any() else _darkest(levels, channels, scale, transparent,
                                                          meta)
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
        p = p[raw_value(value) <= 100.0]
    top = float(p.max(initial=0.0))
    return (f"its darkest pixels read p = {top:.2f}, not above occupied_thresh "
            f"{meta.occupied_thresh:g}; walls drawn grey need a lower --map-occupied-thresh "
            "or --truth-occupied-thresh (occupied_thresh in its YAML)")


def saver_unknown(state: np.ndarray, levels: np.ndarray, channels: int, scale: float,
                  meta: MapMeta, path: Path) -> np.ndarray:
    """``state`` with map_saver's unknown pixels (grey SAVER_UNKNOWN) read as unknown, with a
    warning, where a trinary YAML's ``free_thresh`` reads them as free and the image holds no
    grey value but map_saver's three (SAVER_VALUES): Nav2's map_saver wrote free_thresh 0.25
    beside such images (fixed in navigation2 #5278), and map_server reads every cell the robot
    never saw as free then. The state itself otherwise."""
    if meta.mode != "trinary" or meta.negate:
        return state
    if occupancy_of(np.array([float(SAVER_UNKNOWN)]), meta)[0] >= meta.free_thresh:
        return state
    counts = np.bincount(levels.ravel())
    grey = np.nonzero(counts)[0] / channels * scale
    if not (np.isin(grey, SAVER_VALUES).all() and SAVER_UNKNOWN in grey):
        return state
    _warn(f"{path}: free_thresh {meta.free_thresh:g} reads map_saver's unknown grey "
          f"{SAVER_UNKNOWN} as free; the image holds only map_saver's values "
          f"{', '.join(map(str, SAVER_VALUES))}, so its {SAVER_UNKNOWN} cells are read as "
          "unknown (Nav2's map_saver wrote such YAMLs before navigation2 #5278; "
          "--map-free-thresh or --truth-free-thresh reads them as map_server does)")
    unknown = levels == round(SAVER_UNKNOWN * channels / scale)
    return np.where(unknown & (state == FREE), np.int8(UNKNOWN), state).astype(np.int8)


def open_outside(state: np.ndarray, resolution: float) -> np.ndarray:
    """``state`` (int8 cells of ``resolution`` metres) with the outside of a building drawn
    solid read as its face: in occupied regions that reach the image's border, the cells of
    parts thicker than OUTSIDE_M (an opening by a disc of half that) and deeper than FACE_M
    metres inside the region are UNKNOWN. The image goes on beyond its border as it is there,
    so a wall drawn along the border keeps every cell, and so do walls and furniture joined to
    the border (none that thick) and a region with no face (an all-black image). The state
    itself when no border cell is occupied, or when a cell is wider than FACE_M (a face
    thinner than a cell cannot be drawn: every cell is kept)."""
    occupied = state == OCCUPIED
    if resolution > FACE_M:
        return state
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
        if resolution is None or is_map_yaml(beside[0]):
            raise
        _warn(f"{beside[0]}: ignored, not a map_server YAML ({after_path(error)}); "
              f"{image.name} read with the resolution given, {resolution:g} m")
        return MapMeta(resolution=None)
    if not same_file(image, named):
        used = "origin and thresholds" if resolution is not None else \
            "resolution, origin and thresholds"
        _warn(f"{beside[0]}: names image '{as_written(named, beside[0])}', not {image.name}; "
              f"{image.name} read with this YAML's {used} (give the YAML itself to read the "
              "image it names)")
    return meta


def _warn(message: str) -> None:
    """A warning of :func:`_meta_beside`, from :func:`load_occupancy`'s line; shown while no
    other thread captures stderr (the truth is read while the map is), which would swallow it."""
    with stderr_uncaptured():
        warnings.warn(message, stacklevel=3)


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
    """map_server's occupancy probability p of grey values v (0..255), computed as its
    image_loader does: ``(255 - v) / 255``, with v first replaced by ``255 - v`` when
    ``negate``; in ``raw`` mode v rounded to a whole number (half up, as nav2_map_server
    does), in percent."""
    if meta.mode == "raw":
        return raw_value(value) / 100.0
    if meta.negate:
        value = 255.0 - value
    return (255.0 - value) / 255.0


def raw_value(value: np.ndarray) -> np.ndarray:
    """The cell value a ``raw`` map_server map publishes for grey values v: v rounded half up
    (unknown above 100)."""
    return np.floor(np.asarray(value, dtype=np.float64) + 0.5)


def classify(levels: np.ndarray, channels: int, scale: float, transparent: np.ndarray,
             meta: MapMeta) -> np.ndarray:
    """Cell states (int8 OCCUPIED/FREE/UNKNOWN) of :func:`read_levels`' pixels by map_server's
    rule, on their grey values ``level / channels * scale`` (0..255). ``raw`` mode reads the
    value itself, rounded, as occupancy in percent (above 100: unknown) and ignores ``negate``.
    The rule is applied once per possible level, and the pixels look their state up."""
    value = np.arange(int(levels.max(initial=0)) + 1) / channels * scale
    p = occupancy_of(value, meta)
    state = np.full(value.shape, UNKNOWN, dtype=np.int8)
    state[p < meta.free_thresh] = FREE
    state[p > meta.occupied_thresh] = OCCUPIED
    if meta.mode == "raw":
        state[raw_value(value) > 100.0] = UNKNOWN
    state = state[levels]
    state[transparent] = UNKNOWN
    return state
