"""ROS recordings read with ``rosbags`` (pure Python, no ROS install): ROS 1 ``.bag``, ROS 2
bags (a folder with ``metadata.yaml``, or its ``.db3`` / ``.mcap`` file alone, or that file
compressed whole: :mod:`pcmapq.io.bag_files`) and standalone ``.mcap`` files: opening one, its
topics with types, counts and time span, and picking the topic to read. Their maps are
:mod:`pcmapq.io.bag_grids`, their scans and poses :mod:`pcmapq.io.bag_scans`.

One time axis: every time is seconds from the recording's start (its first message, when
recorded), :func:`seconds`; the start itself is seconds of the recording's clock."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pcmapq.core.errors import InputError
from pcmapq.io.bag_files import decompressed, is_compressed, old_format
from pcmapq.io.formats import BAG_SUFFIXES
from pcmapq.io.writers import one_line

#: Message types by role, as rosbags names them (ROS 2 spelling; ROS 1 names are mapped).
GRID = "nav_msgs/msg/OccupancyGrid"
CLOUD, LASER = "sensor_msgs/msg/PointCloud2", "sensor_msgs/msg/LaserScan"
ODOMETRY, POSE = "nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseStamped"

#: The topic a map is taken from when a recording has several grid topics and none is named.
DEFAULT_MAP_TOPIC = "/map"


@dataclass(frozen=True)
class Message:
    """Which message of a recording a map or scan is: its topic, its index among the topic's
    messages (from 0, in time order), when it was recorded (seconds from the recording's
    start) and its header's stamp (seconds of the clock it was stamped with; None without a
    header)."""

    topic: str
    index: int
    time_s: float
    stamp_s: float | None

    def to_dict(self) -> dict[str, object]:
        return {"topic": self.topic, "index": self.index, "time_s": self.time_s,
                "stamp_s": self.stamp_s}


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
    return path.suffix.lower() in BAG_SUFFIXES or is_compressed(path)


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
    storage = decompressed(path) if is_compressed(path) else Path(path)
    try:
        reader = AnyReader([storage], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as exc:  # noqa: BLE001 - rosbags raises many kinds for a bad file
        why = old_format(path, exc) or f"not a readable ROS recording: {one_line(exc)}"
        raise InputError(f"{path}: {why}") from None
    try:
        _check_index(path, reader)
    except InputError:
        reader.close()
        raise
    try:
        yield reader
    finally:
        reader.close()


def _check_index(path: Path, reader: Any) -> None:
    """InputError when an open recording's index (a ROS 2 bag's metadata.yaml) gives a topic a
    name or type that is not text, or a message count, or the recording a start or end, that is
    not a whole number."""
    for c in reader.connections:
        if not isinstance(c.topic, str) or not isinstance(c.msgtype, str):
            raise InputError(f"{path}: a topic {c.topic!r} of type {c.msgtype!r} in its index "
                             "(metadata.yaml): not a name")
        if type(c.msgcount) is not int or c.msgcount < 0:
            raise InputError(f"{path}: topic {c.topic}: a message count of {c.msgcount!r} in "
                             "its index (metadata.yaml): not a count")
    for name in ("start_time", "end_time"):
        if type(getattr(reader, name)) is not int:
            raise InputError(f"{path}: a {name.replace('_', ' ')} of "
                             f"{getattr(reader, name)!r} ns in its index (metadata.yaml): not a "
                             "time")


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
    """The messages of the topic :func:`pick` chooses, in time order: (the topic, seconds
    from the recording's start, the message; None without ``decode``)."""
    with opened(path) as reader:
        chosen = pick(path, topics(reader), kinds, topic, default, option)
        connections = [c for c in reader.connections if c.topic == chosen.name]
        for connection, stamp, raw in messages(reader, connections, path):
            yield (chosen, seconds(reader, stamp),
                   deserialised(reader, raw, connection, path) if decode else None)


def messages(reader: Any, connections: list[Any], path: Path) -> Iterator[tuple[Any, int, bytes]]:
    """The raw messages of ``connections`` of an open recording, in time order: (connection,
    nanoseconds of its clock, bytes); InputError naming the file when one cannot be read (a
    recording cut short or damaged past its index)."""
    found = reader.messages(connections=connections)
    while True:
        try:
            item = next(found)
        except StopIteration:
            return
        except Exception as exc:  # noqa: BLE001 - rosbags and its storages raise many kinds
            raise InputError(f"{path}: a message cannot be read (the recording is cut short or "
                             f"damaged): {one_line(exc)}") from None
        yield item


def seconds(reader: Any, stamp: int) -> float:
    """A message time of an open recording (nanoseconds of its clock) as seconds from the
    recording's start: the one time axis of every recording."""
    return (int(stamp) - int(reader.start_time)) / 1e9


def span(reader: Any) -> tuple[float, float] | None:
    """The recording's first and last message times, seconds of its clock; None when it holds
    no message."""
    if not any(c.msgcount for c in reader.connections) or reader.end_time < reader.start_time:
        return None
    return reader.start_time / 1e9, reader.end_time / 1e9


def stamp_of(msg: Any) -> float | None:
    """A message's ``header.stamp``, seconds of the clock it was stamped with; None without
    one."""
    try:
        stamp = msg.header.stamp
        return int(stamp.sec) + int(stamp.nanosec) / 1e9
    except AttributeError:
        return None


def deserialised(reader: Any, raw: bytes, connection: Any, path: Path) -> Any:
    try:
        return reader.deserialize(raw, connection.msgtype)
    except Exception as exc:  # noqa: BLE001
        raise InputError(f"{path}: {connection.topic}: a message cannot be read: "
                         f"{one_line(exc)}") from None
