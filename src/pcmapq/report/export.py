"""Exports for other tools: the map moved into the truth's frame (``--aligned``), the matrix
that moves it (``--transform``) and the map's points with their distance to the truth
(``--distances``). Metres.

Frames (:mod:`pcmapq.frames`). A 2D map (an image, a 2D cloud) is moved by the planar
alignment into the truth's plan, ``p_truth = s * R(yaw) * p_map + t``: the 3x3 matrix of the
JSON's ``alignment``. A 3D cloud keeps its three dimensions and is moved by the whole chain,
one 4x4 matrix: levelled (heights above its floor), moved in the plan (z scaled by s), then
placed on the truth's floor and un-levelled when the truth is a 3D cloud; against a plan
(an image, a 2D cloud) its z is the height above the floor. After a 3D registration the map
already stands in the truth cloud's frame and the planar step is the identity, so its plan is
read with the truth's levelling and the chain is the registration itself.

Distances: both sides 3D clouds, each map point's distance to the nearest truth point in 3D;
otherwise, in the plane, from each map point of the plan (an image's occupied cells, a 2D
cloud's points, a 3D cloud's wall band) to the nearest point of the truth's plan (its
occupied cells, its points or its wall band).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from pcmapq.cells import FREE, OCCUPIED
from pcmapq.config import Settings
from pcmapq.frames import Frames, Levelling
from pcmapq.grid import MetricGrid
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.export import DISTANCE_FIELD, record_dtype, records, write_matrix, write_records
from pcmapq.io.ply import CHUNK
from pcmapq.io.writers import OutputSet, write_ros_map
from pcmapq.plan import MAP_CROP, TRUTH_CROP, cropped, load_input, plan_points
from pcmapq.raster.draw import warp_state
from pcmapq.result import Result
from pcmapq.transform import Similarity2D

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
    """The matrix ``--transform`` writes: 4x4 for a 3D cloud map, else the plan's 3x3."""
    if isinstance(source, PointMap) and source.is_3d:
        return cloud_matrix(result.frames)
    return result.frames.planar.matrix


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
        yield part @ matrix[:3, :3].T + matrix[:3, 3]


def plan_cloud(xy: np.ndarray) -> np.ndarray:
    """Plan points (N, 2) as (N, 3) with z = 0."""
    return np.column_stack([xy, np.zeros(len(xy))])


def band_chunks(points: np.ndarray, level: Levelling, low: float, high: float,
                matrix: np.ndarray) -> list[np.ndarray]:
    """The points of a 3D cloud (N, 3) between ``low`` and ``high`` metres above the floor
    of its levelling (the wall band the run scored), moved by a 4x4 matrix; CHUNK rows read
    at a time."""
    out = []
    for start in range(0, len(points), CHUNK):
        part = np.asarray(points[start:start + CHUNK], dtype=np.float64)
        height = part @ level.rotation[2] - level.floor_z_m
        part = part[(height >= low) & (height <= high)]
        out.append(part @ matrix[:3, :3].T + matrix[:3, 3])
    return out


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
    dtype = record_dtype()
    if source.is_3d:
        chunks = moved(source.points, cloud_matrix(result.frames))
    else:
        chunks = iter([plan_cloud(result.frames.planar.apply(source.points[:, :2]))])
    write_records(path, len(source.points), (records(c, dtype) for c in chunks), dtype,
                  f"pcmapq: {source.path} in the frame of {result.truth_path}, metres", outputs)
    return [path]


def truth_plan(truth: OccupancyMap | PointMap, settings: Settings) -> np.ndarray:
    """The truth's plan points (N, 2) metres: occupied cell centres, points or wall band."""
    if isinstance(truth, OccupancyMap):
        return truth.grid.cell_centres(truth.state == OCCUPIED)
    return plan_points(truth, settings)[0]


def distance_chunks(result: Result, source: OccupancyMap | PointMap,
                    truth: OccupancyMap | PointMap, settings: Settings
                    ) -> tuple[int, Iterator[tuple[np.ndarray, np.ndarray]]]:
    """How many map points get a distance, and (points (n, 3) in the truth's frame,
    distances (n,) metres) chunk by chunk (see the module docstring)."""
    frames = result.frames
    if isinstance(source, PointMap) and source.is_3d and isinstance(truth, PointMap) \
            and truth.is_3d:
        tree = cKDTree(np.asarray(truth.points, dtype=np.float64))
        return len(source.points), ((xyz, tree.query(xyz, workers=-1)[0])
                                    for xyz in moved(source.points, cloud_matrix(frames)))
    tree = cKDTree(truth_plan(truth, settings))
    if isinstance(source, PointMap) and source.is_3d:
        parts = band_chunks(source.points, frames.map_levelling, settings.raster.band_low,
                            settings.raster.band_high, cloud_matrix(frames))
    elif isinstance(source, PointMap):
        parts = [plan_cloud(frames.planar.apply(source.points[:, :2]))]
    else:
        parts = [plan_cloud(frames.planar.apply(
            source.grid.cell_centres(source.state == OCCUPIED)))]
    return sum(map(len, parts)), ((xyz, tree.query(xyz[:, :2], workers=-1)[0])
                                  for xyz in parts)


def colours(distance: np.ndarray, clip: float) -> np.ndarray:
    """(n, 3) uint8 colours of distances (metres) on COLOURS from 0 to ``clip`` metres."""
    from matplotlib import colormaps

    rgba = colormaps[COLOURS](np.clip(distance / clip, 0.0, 1.0))
    return np.round(rgba[:, :3] * 255).astype(np.uint8)


def write_distances(path: Path, result: Result, source: OccupancyMap | PointMap,
                    settings: Settings, outputs: OutputSet | None = None) -> list[Path]:
    """The map's points in the truth's frame with their distance to the truth (float
    ``scalar_distance_m``) and a colour (0 m to the largest ``--tau``), as a binary PLY (with
    ``outputs``: staged there, written when it is committed)."""
    truth = load_input(result.truth_path, settings.truth, TRUTH_CROP)
    count, chunks = distance_chunks(result, source, truth, settings)
    dtype = record_dtype(DISTANCE_FIELD, colour=True)
    clip = max(settings.distances.taus)
    write_records(path, count, (records(xyz, dtype, d, colours(d, clip)) for xyz, d in chunks),
                  dtype, f"pcmapq: {source.path} against {result.truth_path}: {DISTANCE_FIELD}"
                  f" in metres, colour {COLOURS} from 0 to {clip:g} m", outputs)
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
