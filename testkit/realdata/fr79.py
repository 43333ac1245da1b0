"""The Freiburg 079 SLAM map turned by known angles and shifted, then scored against itself:
known answers on a real map's texture. The map (0.05 m per pixel assumed) is turned about its
origin with nearest-neighbour sampling, shifted, and aligned back by ``evaluate``."""

from __future__ import annotations

import tempfile
from pathlib import Path

import cv2
import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.io.writers import write_ros_map

from ..runs import Run, timed_evaluate

#: Assumed resolution of the SLAM map, metres per pixel.
RESOLUTION = 0.05
#: Unknown grey of the turned map's border (map_server reads 153 as unknown).
UNKNOWN_GREY = 153
#: The turns, degrees, and the shift, metres (truth -> map frame).
TURNS = (0.0, 90.0, 123.0, 30.0)
SHIFT = (-3.0, 21.0)


def turned(image: np.ndarray, tf: Similarity2D, folder: Path) -> Path:
    """The map image moved by ``tf`` (truth -> map frame), written as a ROS map."""
    rows, cols = image.shape
    src = MetricGrid(RESOLUTION, (0.0, 0.0, 0.0), (rows, cols))
    corners = src.pixels_to_xy([[0, 0], [cols, 0], [0, rows], [cols, rows]])
    dst = MetricGrid.covering(tf.apply(corners), RESOLUTION)
    m = src.xy_to_pixel_matrix() @ tf.inverse().matrix @ dst.pixel_to_xy_matrix()
    out = cv2.warpAffine(image, m[:2], dst.shape[::-1], borderValue=UNKNOWN_GREY,
                         flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP)
    return write_ros_map(folder / f"turned_{tf.yaw_deg:.0f}.png", out, RESOLUTION,
                         dst.origin[:2])


def turn(source: Path, degrees: float) -> Run:
    """The map turned by ``degrees`` and shifted, scored against itself."""
    image = cv2.imread(str(source), cv2.IMREAD_GRAYSCALE)
    with tempfile.TemporaryDirectory(prefix="pcmapq_fr79_") as tmp:
        truth = write_ros_map(Path(tmp) / "fr79.png", image, RESOLUTION)
        tf = Similarity2D(*SHIFT, np.radians(degrees))
        return timed_evaluate(turned(image, tf, Path(tmp)), truth)
