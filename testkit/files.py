"""Synthetic maps written as the files a user gives pcmapq: wall segments (metres) drawn as a
ROS map (PNG and its YAML), points saved as .npy, map_server YAMLs, plain images."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from pcmapq.core.transform import Similarity2D
from pcmapq.io.writers import write_ros_map

from . import synth
from .paths import SAMPLE


def write_image_map(segments: np.ndarray, path: Path, resolution: float = 0.05) -> Path:
    """Render wall segments (metres) as a ROS map: ``path`` (.png) plus a YAML beside it."""
    grid = synth.plan_grid(segments, resolution)
    return write_ros_map(path, synth.render(segments, grid), resolution, grid.origin[:2])


def write_cloud_map(points: np.ndarray, path: Path) -> Path:
    """Save points (N, 2 or 3, metres) as .npy."""
    np.save(path, points)
    return path


def in_map_frame(segments: np.ndarray, tf: Similarity2D) -> np.ndarray:
    """The plan as seen in a map frame, where ``p_truth = tf(p_map)``."""
    return synth.transform_segments(segments, tf.inverse())


def write_png(path: Path, pixels: list[list[int]] | np.ndarray) -> Path:
    """Grey values (0..255) as a PNG."""
    assert cv2.imwrite(str(path), np.asarray(pixels, dtype=np.uint8))
    return path


def sample_yaml(folder: Path, **fields: str) -> Path:
    """A map_server YAML (``m.yaml`` in ``folder``) naming a copy of the sample's truth image,
    with ``fields`` written as given (text: YAML reads them as it reads a user's file)."""
    (folder / "truth.png").write_bytes((SAMPLE / "truth.png").read_bytes())
    text = {"image": "truth.png", "resolution": "0.05", "origin": "[0.0, 0.0, 0.0]", **fields}
    path = folder / "m.yaml"
    path.write_text("".join(f"{k}: {v}\n" for k, v in text.items()))
    return path


def read_cloud(path) -> dict[str, np.ndarray]:
    """A PLY/PCD's attributes as NumPy arrays, read by Open3D."""
    import open3d as o3d

    cloud = o3d.t.io.read_point_cloud(str(path))
    return {key: cloud.point[key].numpy() for key in cloud.point}
