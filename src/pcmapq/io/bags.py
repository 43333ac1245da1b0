"""ROS recordings read with ``rosbags`` (pure Python, no ROS install): ROS 1 ``.bag``, ROS 2
bags (a folder with ``metadata.yaml``, or its ``.db3`` / ``.mcap`` file alone) and standalone
``.mcap`` files: opening one, its topics with types, counts and time span, and picking the topic
to read. Their maps are :mod:`pcmapq.io.bag_grids`, their scans and poses
:mod:`pcmapq.io.bag_scans`. Times are seconds of the recording's clock (when each message was
recorded)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pcmapq.core.errors import InputError
from pcmapq.io.formats import BAG_SUFFIXES
from pcmapq.io.writers import one_line

#: Message types by role, as rosbags names them (ROS 2 spelling; ROS 1 names are mapped).
GRID = "nav_msgs/msg/OccupancyGrid"
CLOUD, LASER = "sensor_msgs/msg/PointCloud2", "sensor_msgs/msg/LaserScan"
ODOMETRY, POSE = "nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseStamped"

#: The topic a map is taken from when a recording has several grid topics and none is named.
DEFAULT_MAP_TOPIC = "/map"


@dataclass(frozen=True)
class Topic:
    """One topic of a recording: name, message type, message count."""

    name: str
    msgtype: str
    count: int


def is_bag(path: Path) -> bool:
    """Whether ``path`` is a recording: a bag or MCAP file, or a ROS 2 bag folder."""
    if path.is_dir():
        return (path / "metadata.yaml").is_file()
    return path.suffix.lower() in BAG_SUFFIXES


@contextmanager
def opened(path: Path) -> Iterator[Any]:
    """The recording open (a rosbags ``AnyReader``); InputError naming the file when it is not
    one, or is truncated or empty."""
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:  # pragma: no cover - a base dependency
        raise InputError(f"{path}: reading ROS recordings needs rosbags: pip install rosbags"
                         ) from None
    if not Path(path).exists():
        raise InputError(f"{path}: not found")
    try:
        reader = AnyReader([Path(path)], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as exc:  # noqa: BLE001 - rosbags raises many kinds for a bad file
        raise InputError(f"{path}: not a readable ROS recording: {one_line(exc)}") from None
    try:
        yield reader
    finally:
        reader.close()


def topics(reader: Any) -> list[Topic]:
    """Every topic of an open recording, by name, with its type and message count."""
    counts: dict[tuple[str, str], int] = {}
    for c in reader.connections:
        key = (c.topic, c.msgtype)
        counts[key] = counts.get(key, 0) + c.msgcount
    return [Topic(name, kind, n) for (name, kind), n in sorted(counts.items())]


def listing(found: list[Topic]) -> str:
    """Topics as one line: ``/map (nav_msgs/msg/OccupancyGrid, 12), /scan (...)``."""
    return ", ".join(f"{t.name} ({t.msgtype}, {t.count})" for t in found) or "none"


def pick(path: Path, found: list[Topic], kinds: tuple[str, ...], given: str | None,
         default: str | None, option: str) -> Topic:
    """The topic to read: ``given``; else the only one of ``kinds``; else ``default`` among
    them. InputError (one line listing the recording's topics) otherwise."""
    fitting = [t for t in found if t.msgtype in kinds]
    what = " or ".join(k.replace("/msg/", "/") for k in kinds)
    if given is not None:
        hit = [t for t in found if t.name == given]
        if not hit:
            raise InputError(f"{path}: no topic {given!r} ({option}); topics: {listing(found)}")
        if hit[0].msgtype not in kinds:
            raise InputError(f"{path}: topic {given!r} is {hit[0].msgtype}, not {what}; topics: "
                             f"{listing(found)}")
        return hit[0]
    if len(fitting) == 1:
        return fitting[0]
    chosen = [t for t in fitting if t.name == default]
    if chosen:
        return chosen[0]
    if not fitting:
        raise InputError(f"{path}: no {what} topic; topics: {listing(found)}")
    raise InputError(f"{path}: {len(fitting)} {what} topics, name one with {option}: "
                     f"{listing(fitting)}")


def has_grids(path: Path, topic: str | None = None) -> bool:
    """Whether ``path`` is a recording holding an OccupancyGrid topic (or ``topic`` is named:
    then its errors are the grid reader's)."""
    if not is_bag(Path(path)) or not Path(path).exists():
        return False
    if topic is not None:
        return True
    with opened(Path(path)) as reader:
        return any(t.msgtype == GRID for t in topics(reader))


def topic_messages(path: Path, kinds: tuple[str, ...], topic: str | None, default: str | None,
                   option: str, decode: bool = True) -> Iterator[tuple[Topic, float, Any]]:
    """The messages of the topic :func:`pick` chooses, in time order: (the topic, seconds of
    the recording's clock, the message; None without ``decode``)."""
    with opened(path) as reader:
        chosen = pick(path, topics(reader), kinds, topic, default, option)
        connections = [c for c in reader.connections if c.topic == chosen.name]
        for connection, stamp, raw in reader.messages(connections=connections):
            yield (chosen, stamp / 1e9,
                   deserialised(reader, raw, connection, path) if decode else None)


def span(reader: Any) -> tuple[float, float]:
    """The recording's first and last message times, seconds."""
    return reader.start_time / 1e9, reader.end_time / 1e9


def deserialised(reader: Any, raw: bytes, connection: Any, path: Path) -> Any:
    try:
        return reader.deserialize(raw, connection.msgtype)
    except Exception as exc:  # noqa: BLE001
        raise InputError(f"{path}: {connection.topic}: a message cannot be read: "
                         f"{one_line(exc)}") from None
