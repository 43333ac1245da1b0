"""Exports for other tools: the map moved into the truth's frame (``--aligned``), the matrix
that moves it (``--transform``) and the map's points with their distance to the truth
(``--distances``). Metres.

Frames (:mod:`pcmapq.core.frames`). A 2D map (an image, a 2D cloud) is moved by the planar
alignment into the truth's plan, ``p_truth = s * R(yaw) * p_map + t``: the 3x3 matrix of the
JSON's ``alignment``. A 3D cloud keeps its three dimensions and is moved by the whole chain,
one 4x4 matrix: levelled (heights above its floor), moved in the plan (z scaled by s), then
placed on the truth's floor and un-levelled when the truth is a 3D cloud; against a plan
(an image, a 2D cloud) its z is the height above the floor. After a 3D registration the map
already stands in the truth cloud's frame and the planar step is the identity, so its plan is
read with the truth's levelling and the chain is the registration itself.

Distances: the points the JSON's accuracy is computed on, with their distances, so that the
file's statistics are the JSON's: both sides 3D clouds, the map's voxel centroids and their
distance to the nearest truth voxel centroid in 3D (``distances_3d.accuracy_m``); otherwise the
map's occupied cells on the truth's grid and their distance in the plan to the nearest truth
cell (``distances.accuracy_m``).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np

from pcmapq.core.cells import FREE, OCCUPIED
from pcmapq.core.frames import Frames, Levelling
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D, affine
from pcmapq.evaluation.inputs import MAP_CROP, TRUTH_CROP, cropped, load_input
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.export import DISTANCE_FIELD, record_dtype, records, write_matrix, write_records
from pcmapq.io.ply import CHUNK
from pcmapq.io.writers import SCAN, OutputSet, write_ros_map
from pcmapq.metrics.distances import accuracy_2d, accuracy_3d, nearest_distance
from pcmapq.raster.draw import warp_state
from pcmapq.results.result import Result
from pcmapq.settings import Settings

#: map_server grey values of an occupied, a free and an unknown cell (negate 0).
ROS_OCCUPIED, ROS_FREE, ROS_UNKNOWN = 0, 254, 205
#: Colour map of the distance cloud, from 0 m to the largest F-score threshold.
COLOURS = "viridis"


def lift(tf: Similarity2D) -> np.ndarray:
    """4x4 of a plan similarity acting on 3D points: x, y as ``tf``, z scaled by its scale."""
    out = np.eye(4)
    out[:2, :2], out[:2, 3] = tf.matrix[:2, :2], tf.matrix[:2, 2]
    out[2, 2] = tf.scale
    return out


def levelling_matrix(level: Levelling | None) -> np.ndarray:
    """4x4 taking a cloud to its plan frame with heights above its floor (identity for a 2D
    input): ``p -> rotation @ p - (0, 0, floor_z_m)``."""
    out = np.eye(4)
    if level is not None:
        out[:3, :3] = level.rotation
        out[2, 3] = -level.floor_z_m
    return out


def cloud_matrix(frames: Frames) -> np.ndarray:
    """4x4 map cloud -> truth frame (see the module docstring), metres."""
    truth = levelling_matrix(frames.truth_levelling)
    if frames.registration_3d is not None:
        first = truth @ np.asarray(frames.registration_3d)
    else:
        first = levelling_matrix(frames.map_levelling)
    return np.linalg.inv(truth) @ lift(frames.planar) @ first


def map_matrix(result: Result, source: OccupancyMap | PointMap) -> np.ndarray:
    """The 4x4 matrix ``--transform`` writes, as CloudCompare and Open3D apply it: a 3D cloud
    map's whole chain; for a 2D map the plan's similarity lifted (:func:`lift`: z scaled by
    its scale, so a 2D map's z = 0 stays 0), the JSON's 3x3 ``alignment.matrix`` in 3D."""
    if isinstance(source, PointMap) and source.is_3d:
        return cloud_matrix(result.frames)
    return lift(result.frames.planar)


def load_source(result: Result, given: Path | PointMap, settings: Settings
                ) -> OccupancyMap | PointMap:
    """The map as the run read it, cropped as it was (a map built from scans is passed as it
    is)."""
    if isinstance(given, PointMap):
        return cropped(given, settings.map, MAP_CROP)
    fallback = result.grid.resolution if settings.alignment.scale else None
    return load_input(given, settings.map, MAP_CROP, fallback)


def moved(points: np.ndarray, matrix: np.ndarray) -> Iterator[np.ndarray]:
    """Points (N, 3) metres, any float type, moved by a 4x4 matrix, CHUNK rows at a time
    (float64)."""
    for start in range(0, len(points), CHUNK):
        part = np.asarray(points[start:start + CHUNK], dtype=np.float64)
        yield affine(part, matrix)


def plan_cloud(xy: np.ndarray) -> np.ndarray:
    """Plan points (N, 2) as (N, 3) with z = 0."""
    return np.column_stack([xy, np.zeros(len(xy))])


def aligned_grid(source: MetricGrid, tf: Similarity2D, truth: MetricGrid) -> MetricGrid:
    """The grid an image map is drawn on in the truth's frame: the truth's cell size and cell
    lattice (yaw 0), just covering the moved image."""
    rows, cols = source.shape
    corners = tf.apply(source.pixels_to_xy(np.array(
        [[-0.5, -0.5], [cols - 0.5, -0.5], [cols - 0.5, rows - 0.5], [-0.5, rows - 0.5]])))
    res = truth.resolution
    anchor = np.array(truth.origin[:2]) if truth.origin[2] == 0.0 else np.zeros(2)
    lo = anchor + np.floor((corners.min(axis=0) - anchor) / res + 1e-9) * res
    cols, rows = np.maximum(np.ceil((corners.max(axis=0) - lo) / res - 1e-9), 1).astype(int)
    return MetricGrid(res, (float(lo[0]), float(lo[1]), 0.0), (int(rows), int(cols)))


def write_aligned(path: Path, result: Result, source: OccupancyMap | PointMap,
                  outputs: OutputSet | None = None) -> list[Path]:
    """The map moved into the truth's frame: an image map as a map_server PNG/PGM + YAML on
    :func:`aligned_grid`, a cloud as PLY/PCD. Returns the files written (with ``outputs``:
    staged there, written when it is committed)."""
    if isinstance(source, OccupancyMap):
        tf = result.frames.planar
        grid = aligned_grid(source.grid, tf, result.grid)
        state = warp_state(source.state, source.grid, tf, grid)
        image = np.full(state.shape, ROS_UNKNOWN, dtype=np.uint8)
        image[state == FREE], image[state == OCCUPIED] = ROS_FREE, ROS_OCCUPIED
        write_ros_map(path, image, grid.resolution, grid.origin[:2], outputs)
        return [path, path.with_suffix(".yaml")]
    dtype = record_dtype(None if source.scan is None else SCAN)
    if source.is_3d:
        chunks = moved(source.points, cloud_matrix(result.frames))
    else:
        chunks = iter([plan_cloud(result.frames.planar.apply(source.points[:, :2]))])
    write_records(path, len(source.points), _with_scans(chunks, source.scan, dtype), dtype,
                  f"pcmapq: {source.path} in the frame of {result.truth_path}, metres", outputs)
    return [path]


def _with_scans(chunks: Iterator[np.ndarray], scan: np.ndarray | None,
                dtype: np.dtype) -> Iterator[np.ndarray]:
    """Records of ``dtype`` of the points' chunks (n, 3), each with its points' scans taken in
    turn from ``scan`` (N,) when the map carries them (None: without)."""
    start = 0
    for chunk in chunks:
        yield records(chunk, dtype, None if scan is None else scan[start:start + len(chunk)])
        start += len(chunk)


def accuracy_points(result: Result, source: OccupancyMap | PointMap,
                    settings: Settings) -> tuple[str, np.ndarray, np.ndarray]:
    """The points (n, 3, truth frame) and distances (n,) metres the JSON's accuracy is computed
    on, and that figure's JSON path: both inputs 3D clouds, the map's voxel centroids and
    their 3D distances (``distances_3d.accuracy_m``); otherwise the map's occupied cells on the
    truth's grid, z = 0, and their distances in the plan (``distances.accuracy_m``)."""
    if result.distances_3d is not None:
        truth = load_input(result.truth_path, settings.truth, TRUTH_CROP)
        xyz = np.vstack(list(moved(source.points, cloud_matrix(result.frames))))
        points, d = accuracy_3d(xyz, np.asarray(truth.points, dtype=np.float64),
                                settings.raster.cloud_resolution)
        return "distances_3d.accuracy_m", points, d
    if result.map_occupied is None or result.truth_occupied is None:
        raise ValueError("--distances needs the rasters of a run, not of a JSON read back")
    xy, d = accuracy_2d(result.map_occupied, result.grid,
                        nearest_distance(result.truth_occupied, result.grid))
    return "distances.accuracy_m", plan_cloud(xy), d


def colours(distance: np.ndarray, clip: float) -> np.ndarray:
    """(n, 3) uint8 colours of distances (metres) on COLOURS from 0 to ``clip`` metres."""
    from matplotlib import colormaps

    rgba = colormaps[COLOURS](np.clip(distance / clip, 0.0, 1.0))
    return np.round(rgba[:, :3] * 255).astype(np.uint8)


def write_distances(path: Path, result: Result, source: OccupancyMap | PointMap,
                    settings: Settings, outputs: OutputSet | None = None) -> list[Path]:
    """The points the JSON's accuracy is computed on, in the truth's frame, each with its
    distance to the truth (float ``scalar_distance_m``, :func:`accuracy_points`: their
    statistics are the JSON's) and a colour (0 m to the largest ``--tau``), as a binary PLY
    (with ``outputs``: staged there, written when it is committed)."""
    figure, xyz, d = accuracy_points(result, source, settings)
    dtype = record_dtype(DISTANCE_FIELD, colour=True)
    clip = max(settings.distances.taus)
    write_records(path, len(xyz), iter([records(xyz, dtype, d, colours(d, clip))]), dtype,
                  f"pcmapq: {source.path} against {result.truth_path}: {DISTANCE_FIELD} in "
                  f"metres, the distances of the JSON's {figure}; colour {COLOURS} from 0 to "
                  f"{clip:g} m", outputs)
    return [path]


def write_exports(result: Result, given: Path | PointMap, settings: Settings, *,
                  aligned: Path | None = None, transform: Path | None = None,
                  distances: Path | None = None, outputs: OutputSet | None = None
                  ) -> list[Path]:
    """Write the exports asked for (``--aligned``, ``--transform``, ``--distances``); the map
    (``given``: its file, or a map built from scans) is read again only when one is asked.
    Returns the files written (with ``outputs``: staged there, written when it is
    committed)."""
    if aligned is None and transform is None and distances is None:
        return []
    source = load_source(result, given, settings)
    written = []
    if aligned is not None:
        written += write_aligned(aligned, result, source, outputs)
    if transform is not None:
        write_matrix(transform, map_matrix(result, source), outputs)
        written.append(transform)
    if distances is not None:
        written += write_distances(distances, result, source, settings, outputs)
    return written
