"""An occupancy image reads as map_server reads it, cell for cell, on any image at any
resolution: random small grey, colour and 16-bit images with random thresholds, ``negate`` and
mode, against map_server's rule written out here (nav2_map_server's ``loadMapFromFile``; for a
``scale`` image's grey cells ROS 1 map_server's 1 + 98 * ratio, never 0 or 100: neither
occupied nor free), the cells read as a published grid is (100 occupied, 0 free, any other
value unknown; a ``raw`` value v as p = v / 100 against the thresholds). The one documented
departure (map_saver's unknown grey beside a Nav2 YAML, docs/formats.md) is part of the rule."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.evaluation.inputs import MAP_CROP, load_input
from pcmapq.io import load_map
from pcmapq.settings import SourceConfig

#: Cell sizes the rule must hold at, metres: a face of a building (0.15 m) is wider than the
#: coarse ones' cells, narrower than the fine ones'.
RESOLUTIONS = (0.01, 0.05, 0.2, 1.0, 5.0)
SAVER = (0, 205, 254)


def map_server(image: np.ndarray, occupied: float, free: float, negate: bool,
               mode: str) -> np.ndarray:
    """Cell states (rows, cols) of an image without alpha (grey (rows, cols) or colour
    (rows, cols, 3), 8 or 16 bit) by map_server's rule, pixel by pixel: the mean of the
    channels on a 0..255 scale (a 16-bit value times 255 / 65535), ``255 - mean`` when
    ``negate``, occ = (255 - mean) / 255 (ROS 1 image_loader's arithmetic); ``raw``: the mean
    rounded half up (nav2_map_server), ``negate`` ignored."""
    top = float(np.iinfo(image.dtype).max)
    grey = image.reshape(*image.shape[:2], -1).astype(np.int64)
    out = np.full(image.shape[:2], UNKNOWN, dtype=np.int8)
    for (r, c), _ in np.ndenumerate(out):
        mean = int(grey[r, c].sum()) / grey.shape[2] * (255.0 / top)
        if mode == "raw":
            value = math.floor(mean + 0.5)
            if value > 100:
                continue
            p = value / 100.0
            out[r, c] = OCCUPIED if p > occupied else FREE if p < free else UNKNOWN
            continue
        if negate:
            mean = 255.0 - mean
        occ = (255.0 - mean) / 255.0
        if occupied < occ:
            out[r, c] = OCCUPIED
        elif occ < free:
            out[r, c] = FREE
        # else: -1 (trinary) or 1 + 98 * ratio (scale): neither occupied nor free
    return out


def with_saver_rule(state: np.ndarray, image: np.ndarray, free: float, negate: bool,
                    mode: str) -> np.ndarray:
    """The documented departure: a trinary, not negated image holding map_saver's three grey
    values only (205 among them), whose free_thresh reads 205 as free, has its 205 cells
    unknown."""
    values = set(np.unique(image).tolist())
    reads_free = (255 - 205) / 255 < free
    if (mode == "trinary" and not negate and image.dtype == np.uint8 and image.ndim == 2
            and values <= set(SAVER) and 205 in values and reads_free):
        return np.where(image == 205, np.int8(UNKNOWN), state)
    return state


GREYS = st.one_of(st.sampled_from(SAVER), st.integers(0, 255))
IMAGES = st.one_of(
    arrays(np.uint8, st.tuples(st.integers(1, 12), st.integers(1, 12)), elements=GREYS),
    arrays(np.uint8, st.tuples(st.integers(1, 8), st.integers(1, 8), st.just(3)),
           elements=st.integers(0, 255)),
    arrays(np.uint16, st.tuples(st.integers(1, 8), st.integers(1, 8)),
           elements=st.integers(0, 65535)),
)
#: Thresholds on and between the values a grey level gives (k / 255), 0 <= free < occupied <= 1.
LEVELS = st.one_of(st.integers(0, 255).map(lambda k: k / 255), st.floats(0.0, 1.0))
THRESHOLDS = st.tuples(LEVELS, LEVELS).filter(lambda t: t[0] != t[1]).map(sorted)


def write_map(folder: Path, image: np.ndarray, resolution: float, occupied: float,
              free: float, negate: bool, mode: str) -> Path:
    """The image as a PNG with its map_server YAML; the YAML's path."""
    assert cv2.imwrite(str(folder / "m.png"), image[..., ::-1] if image.ndim == 3 else image)
    yaml = folder / "m.yaml"
    yaml.write_text(f"image: m.png\nresolution: {resolution!r}\norigin: [0.0, 0.0, 0.0]\n"
                    f"negate: {int(negate)}\noccupied_thresh: {occupied!r}\n"
                    f"free_thresh: {free!r}\nmode: {mode}\n")
    return yaml


@settings(max_examples=80, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(image=IMAGES, thresholds=THRESHOLDS, negate=st.booleans(),
       mode=st.sampled_from(["trinary", "scale", "raw"]),
       resolution=st.sampled_from(RESOLUTIONS))
def test_every_cell_is_map_servers(tmp_path_factory: pytest.TempPathFactory, image: np.ndarray,
                                   thresholds: list[float], negate: bool, mode: str,
                                   resolution: float) -> None:
    free, occupied = thresholds
    folder = tmp_path_factory.mktemp("map")
    yaml = write_map(folder, image, resolution, occupied, free, negate, mode)
    want = with_saver_rule(map_server(image, occupied, free, negate, mode), image, free, negate,
                           mode)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the departure's warning
        got = load_map(yaml)
    np.testing.assert_array_equal(got.state, want)
    assert got.grid.resolution == resolution


def test_a_coarse_map_keeps_every_occupied_cell_in_the_evaluation(tmp_path: Path) -> None:
    """A 10 x 10 ROS map at 1 m per cell, 20 % of it occupied, a 3 x 3 block in a corner: read
    and evaluated with all 20 cells (a 0.15 m face cannot be drawn in 1 m cells)."""
    image = np.full((10, 10), 254, np.uint8)
    image[:3, :3] = 0
    image[5, 5:9], image[7:9, 2], image[9, 9], image[4, 4], image[2, 7] = 0, 0, 0, 0, 0
    image[6, 0], image[0, 9] = 0, 0
    yaml = write_map(tmp_path, image, 1.0, 0.65, 0.196, False, "trinary")
    assert np.count_nonzero(load_map(yaml).state == OCCUPIED) == 20
    evaluated = load_input(yaml, SourceConfig(), MAP_CROP)
    assert np.count_nonzero(evaluated.state == OCCUPIED) == 20
