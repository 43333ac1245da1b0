"""The ``nav_msgs/OccupancyGrid`` messages of a ROS recording (:mod:`pcmapq.io.bags`) as
occupancy maps, read as map_server reads a saved map: a cell of -1 is unknown, else
``p = value / 100`` is occupied above ``occupied_thresh`` and free below ``free_thresh``.
Times are seconds from the recording's start (:func:`pcmapq.io.bags.seconds`); each map names
its message (:class:`~pcmapq.io.bags.Message`)."""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq.core import memory
from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.io.bags import (
    DEFAULT_MAP_TOPIC,
    GRID,
    Message,
    deserialised,
    messages,
    opened,
    pick,
    seconds,
    stamp_of,
    topic_messages,
    topics,
)
from pcmapq.io.map_yaml import MapMeta, Thresholds
from pcmapq.io.occupancy import OccupancyMap
from pcmapq.io.writers import one_line


def grids(path: Path, topic: str | None = None, thresholds: Thresholds | None = None,
          option: str = "--map-topic", memory_limit: int | None = None
          ) -> Iterator[tuple[float, OccupancyMap]]:
    """Every OccupancyGrid of the recording's map topic, in time order: (seconds from the
    recording's start, map naming its message). A grid the same as the one before (same
    cells, resolution and origin) is left out; one larger than ``memory_limit`` bytes allow
    (None: the default) is refused before it is drawn."""
    last = None
    for index, (chosen, at, msg) in enumerate(
            topic_messages(path, (GRID,), topic, DEFAULT_MAP_TOPIC, option)):
        key = _checked(path, chosen.name, _digest, msg)
        if key == last:
            continue
        last = key
        grid = _checked(path, chosen.name, grid_map, msg, path, chosen.name, thresholds,
                        memory_limit)
        yield at, replace(grid, message=Message(chosen.name, index, at, stamp_of(msg)))


def grid_at(path: Path, topic: str | None = None, at: float | None = None,
            thresholds: Thresholds | None = None, option: str = "--map-topic",
            memory_limit: int | None = None) -> OccupancyMap:
    """The OccupancyGrid of the map topic at ``at`` seconds from the recording's start (the
    last one recorded at or before it), or the last one; InputError when there is none. Only
    that message is decoded."""
    with opened(path) as reader:
        chosen = pick(path, topics(reader), (GRID,), topic, DEFAULT_MAP_TOPIC, option)
        connections = [c for c in reader.connections if c.topic == chosen.name]
        found = None
        for index, (connection, stamp, raw) in enumerate(
                messages(reader, connections, path)):
            t = seconds(reader, stamp)
            if at is not None and t > at:
                break
            found = (index, t, connection, raw)
        if found is None:
            raise InputError(f"{path}: no OccupancyGrid at or before {at:g} s from the "
                             "recording's start" if at is not None
                             else f"{path}: the map topic holds no message")
        index, t, connection, raw = found
        msg = deserialised(reader, raw, connection, path)
    grid = _checked(path, chosen.name, grid_map, msg, path, chosen.name, thresholds,
                    memory_limit)
    return replace(grid, message=Message(chosen.name, index, t, stamp_of(msg)))


def _checked(path: Path, topic: str, function, *args):
    """``function(*args)`` on a message, InputError naming the topic when the message is of
    another shape."""
    try:
        return function(*args)
    except (AttributeError, TypeError, ValueError) as exc:
        raise InputError(f"{path}: {topic}: not an OccupancyGrid as nav_msgs defines it: "
                         f"{one_line(exc)}") from None


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
