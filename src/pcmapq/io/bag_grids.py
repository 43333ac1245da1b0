"""The ``nav_msgs/OccupancyGrid`` messages of a ROS recording (:mod:`pcmapq.io.bags`) as
occupancy maps, read as map_server reads a saved map: a cell of -1 is unknown, else
``p = value / 100`` is occupied above ``occupied_thresh`` and free below ``free_thresh``.
Times are seconds of the recording's clock."""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq.core import memory
from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.io.bags import DEFAULT_MAP_TOPIC, GRID, topic_messages
from pcmapq.io.map_yaml import MapMeta, Thresholds
from pcmapq.io.occupancy import OccupancyMap
from pcmapq.io.writers import one_line


def grids(path: Path, topic: str | None = None, thresholds: Thresholds | None = None,
          option: str = "--map-topic", memory_limit: int | None = None
          ) -> Iterator[tuple[float, OccupancyMap]]:
    """Every OccupancyGrid of the recording's map topic, in time order: (seconds, map). A grid
    the same as the one before (same cells, resolution and origin) is left out; one larger
    than ``memory_limit`` bytes allow (None: the default) is refused before it is drawn."""
    last = None
    for chosen, seconds, msg in topic_messages(path, (GRID,), topic, DEFAULT_MAP_TOPIC, option):
        try:
            key = _digest(msg)
            if key == last:
                continue
            last = key
            grid = grid_map(msg, path, chosen.name, thresholds, memory_limit)
        except (AttributeError, TypeError, ValueError) as exc:  # a message of another shape
            raise InputError(f"{path}: {chosen.name}: not an OccupancyGrid as nav_msgs "
                             f"defines it: {one_line(exc)}") from None
        yield seconds, grid


def grid_at(path: Path, topic: str | None = None, at: float | None = None,
            thresholds: Thresholds | None = None, option: str = "--map-topic",
            memory_limit: int | None = None) -> OccupancyMap:
    """The OccupancyGrid of the map topic at ``at`` seconds of the bag's clock (the last one
    published at or before it), or the last one; InputError when there is none."""
    chosen = None
    for stamp, grid in grids(path, topic, thresholds, option, memory_limit):
        if at is not None and stamp > at:
            break
        chosen = grid
    if chosen is None:
        raise InputError(f"{path}: no OccupancyGrid at or before {at:g} s" if at is not None
                         else f"{path}: the map topic holds no message")
    return chosen


def grid_map(msg: Any, path: Path, topic: str, thresholds: Thresholds | None = None,
             memory_limit: int | None = None) -> OccupancyMap:
    """An OccupancyGrid message as an occupancy map: its cells read as map_server reads a saved
    map (``thresholds``: its occupied and free thresholds; negate does not apply to a grid's
    values), row 0 the grid's top (the message's last row: its rows start at the origin)."""
    info = msg.info
    rows, cols = int(info.height), int(info.width)
    memory.guard(memory.needed_bytes(rows * cols, 0, 0.0, 0), memory_limit,
                 f"{path}: {topic}: an OccupancyGrid of {cols} x {rows} cells")
    data = np.asarray(msg.data, dtype=np.int8)
    if rows * cols == 0 or data.size != rows * cols or not info.resolution > 0:
        raise InputError(f"{path}: {topic}: an OccupancyGrid of {cols} x {rows} cells at "
                         f"{info.resolution} m holds {data.size} values")
    resolution = float(str(np.float32(info.resolution)))  # a float32: 0.05, not 0.0500000007
    meta = MapMeta(resolution=resolution)
    if thresholds is not None:
        meta = thresholds.apply(meta)
    state = np.full(data.shape, UNKNOWN, dtype=np.int8)
    known = data >= 0  # p = value / 100, compared in percent
    state[known & (data > 100.0 * meta.occupied_thresh)] = OCCUPIED
    state[known & (data < 100.0 * meta.free_thresh)] = FREE
    q = info.origin.orientation
    yaw = float(np.arctan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z)))
    grid = MetricGrid(resolution,
                      (float(info.origin.position.x), float(info.origin.position.y), yaw),
                      (rows, cols))
    return OccupancyMap(path, grid, np.flipud(state.reshape(rows, cols)).copy(),
                        kind="OccupancyGrid")


def _digest(msg: Any) -> bytes:
    """What makes two grids the same map: cells, resolution, size and origin."""
    info, o = msg.info, msg.info.origin
    head = np.array([info.resolution, info.width, info.height, o.position.x, o.position.y,
                     o.orientation.z, o.orientation.w], dtype=np.float64)
    return hashlib.sha256(head.tobytes() + np.asarray(msg.data, np.int8).tobytes()).digest()
