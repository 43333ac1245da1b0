"""Halmstad: robot maps against their building's layout, scale unknown: the files, the
settings of the full pipeline, the annotated keypoint pairs and how far the pipeline's
alignment carries them from their partners."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np

from pcmapq.io import OccupancyMap, load_map
from pcmapq.io.map_yaml import MapMeta
from pcmapq.io.occupancy import classify, read_levels
from pcmapq.raster.draw import OCCUPIED
from pcmapq.results.result import Result
from pcmapq.settings import AlignmentConfig, Settings, SourceConfig

from ..runs import Run, timed_evaluate

#: Maps scored with the full pipeline (one per building).
MAPS = ("E5_09", "F5_01", "HIH_01", "KPT4A_01")
#: Assumed resolution of every layout image, metres per pixel.
PLAN_RESOLUTION = 0.05
SETTINGS = Settings(alignment=AlignmentConfig(scale=True),
                    truth=SourceConfig(resolution=PLAN_RESOLUTION))
#: A layout's wall cores: pixels darker than this grey.
DARK = 50
#: Maps whose keypoint association is broken (../shared/README.md): no residual of theirs means
#: anything.
BROKEN_ANNOTATIONS = frozenset({"E5_08"})
#: map_server's default thresholds (a map without YAML or options).
ROS = MapMeta(resolution=None)


def walls_read_occupied(image: Path, dark: float = DARK) -> float:
    """Share of an image's dark pixels (grey < ``dark``, opaque) that pcmapq's loader, with
    ROS's default thresholds, reads as occupied."""
    levels, channels, scale, transparent = read_levels(image)
    state = classify(levels, channels, scale, transparent, ROS)
    grey = levels / channels * scale
    walls = (grey < dark) & ~transparent
    return float((state[walls] == OCCUPIED).mean()) if walls.any() else 0.0


def with_yaml(image: Path, folder: Path, resolution: float, **thresholds: float) -> Path:
    """A copy of ``image`` in ``folder`` with a map_server YAML beside it (origin 0, the given
    thresholds over ROS's defaults); returns the YAML's path."""
    copy = folder / image.name
    shutil.copyfile(image, copy)
    meta = {"occupied_thresh": 0.65, "free_thresh": 0.196, **thresholds}
    yaml_path = copy.with_suffix(".yaml")
    yaml_path.write_text(f"image: {copy.name}\nresolution: {resolution}\norigin: [0, 0, 0]\n"
                         f"negate: 0\noccupied_thresh: {meta['occupied_thresh']}\n"
                         f"free_thresh: {meta['free_thresh']}\n")
    return yaml_path


def halmstad_truth(layout: Path, folder: Path) -> Path:
    """The layout as pcmapq should read it: the image itself when ROS's thresholds read its
    walls as occupied, else a copy with a YAML whose occupied threshold does."""
    if walls_read_occupied(layout) >= 0.95:
        return layout
    return with_yaml(layout, folder, PLAN_RESOLUTION, occupied_thresh=0.55)


def keypoint_pairs(data: Path, name: str, building: str) -> tuple[np.ndarray, np.ndarray]:
    """(map keypoints, layout keypoints), (K, 2) pixels, paired row by row; pairs with a missing
    side (None rows of object arrays) are dropped. ``data``: the Halmstad folder."""
    notes = data / "annotations"
    pairs = np.load(notes / f"association_{name}_{building}_layout.npy", allow_pickle=True)
    pairs = np.array([p for p in pairs if p[0] is not None and p[1] is not None], dtype=int)
    map_keys = np.load(notes / f"keypoints_{name}.npy", allow_pickle=True).astype(np.float64)
    layout_keys = np.load(notes / f"keypoints_{building}_layout.npy", allow_pickle=True)
    return map_keys[pairs[:, 0]], layout_keys.astype(np.float64)[pairs[:, 1]]


def fit_residual(map_keys: np.ndarray, layout_keys: np.ndarray) -> float:
    """Median distance, layout pixels, between the annotated map keypoints carried by their own
    least-squares similarity fit onto their layout partners (Umeyama's) and those partners: how
    far the map is from a scaled, turned and shifted copy of the layout (its distortion, and the
    annotations' noise), whatever pcmapq's alignment. Keypoints: (K, 2) pixels."""
    from pcmapq.align.similarity_icp import fit_similarity

    fit = fit_similarity(map_keys, layout_keys)
    return float(np.median(np.linalg.norm(fit.apply(map_keys) - layout_keys, axis=1)))


def keypoint_residual(result: Result, map_path: Path, map_keys: np.ndarray,
                      layout_keys: np.ndarray) -> float:
    """Median distance, layout pixels, between the annotated map keypoints carried by the
    pipeline's alignment and their layout partners. Keypoints: (K, 2) pixels, x = column,
    y = rows - 1 - row."""
    source = load_map(map_path, None, PLAN_RESOLUTION)
    if not isinstance(source, OccupancyMap):
        raise TypeError(f"{map_path}: not an image")
    rows = source.grid.shape[0]
    uv = np.column_stack([map_keys[:, 0], rows - 1 - map_keys[:, 1]])
    truth_uv = result.grid.xy_to_pixels(
        result.transform.apply(source.grid.pixels_to_xy(uv)))
    got = np.column_stack([truth_uv[:, 0], result.grid.shape[0] - 1 - truth_uv[:, 1]])
    return float(np.median(np.linalg.norm(got - layout_keys, axis=1)))


def paths(data: Path, name: str) -> tuple[Path, Path]:
    """A map's image and its building's layout."""
    building = name.rsplit("_", 1)[0]
    folder = data / "halmstad" / "maps" / building
    return folder / "pseudo_occupancy" / f"{name}.png", folder / "layout" / f"{building}_layout.png"


def pipeline(data: Path, name: str) -> Run:
    """One map through the pipeline against its layout."""
    map_path, layout = paths(data, name)
    with tempfile.TemporaryDirectory(prefix="pcmapq_halmstad_") as tmp:
        return timed_evaluate(map_path, halmstad_truth(layout, Path(tmp)), SETTINGS)
