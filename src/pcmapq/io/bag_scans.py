"""The scans and poses of a ROS recording (:mod:`pcmapq.io.bags`): ``sensor_msgs/PointCloud2``
and ``sensor_msgs/LaserScan`` messages as points in the sensor's frame, ``nav_msgs/Odometry``
and ``geometry_msgs/PoseStamped`` messages as a pose track, and poses interpolated along it:
a scan farther in time from the nearest pose than :data:`GAP_WARN_S` gets a warning, than
:data:`GAP_MAX_S` is refused. Times are seconds from the recording's start; metres."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import closing
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.words import count, plural
from pcmapq.io.bags import (
    CLOUD,
    LASER,
    ODOMETRY,
    POSE,
    Topic,
    opened,
    pick,
    topic_messages,
    topics,
)

#: PointCloud2 field datatypes (sensor_msgs/PointField) as NumPy types.
FIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}
#: Per-point time fields of a PointCloud2, in the order KISS-ICP's loaders try them.
TIME_FIELDS = ("t", "timestamp", "timestamps", "time", "stamps")
#: The message types of scans.
SCANS = (CLOUD, LASER)
#: Scans farther than this from the nearest pose of their track, seconds, are placed with a
#: warning (their pose is held or interpolated across that gap: 0.5 m at a walking pace).
GAP_WARN_S = 0.5
#: Scans farther than this from the nearest pose of their track, seconds, are refused.
GAP_MAX_S = 5.0


def scan_topic(path: Path, topic: str | None = None) -> Topic:
    """The recording's scan topic: ``topic``, else its only PointCloud2 or LaserScan topic."""
    with opened(path) as reader:
        return pick(path, topics(reader), SCANS, topic, None, "--scan-topic")


def scans(path: Path, topic: str | None = None
          ) -> Iterator[tuple[float, np.ndarray, np.ndarray]]:
    """The scans of the recording's scan topic in time order: (seconds, points (N, 3) float64
    metres in the sensor's frame, per-point times (N,) or (0,)). A PointCloud2 keeps its
    finite x, y, z and a time field if it has one; a LaserScan its returns within its range
    limits (z = 0), timed by ``time_increment``."""
    for chosen, seconds, msg in topic_messages(path, SCANS, topic, None, "--scan-topic"):
        if chosen.msgtype == LASER:
            yield seconds, *laser_points(msg)
        else:
            yield seconds, *cloud_points(msg, path, chosen.name)


def laser_points(msg: Any) -> tuple[np.ndarray, np.ndarray]:
    """A LaserScan's returns as points (N, 3) metres (z = 0) and their times (N,) seconds
    from the first beam (empty when the scan gives no time between beams)."""
    ranges = np.asarray(msg.ranges, dtype=np.float64)
    index = np.arange(len(ranges))
    angles = msg.angle_min + index * msg.angle_increment
    ok = np.isfinite(ranges) & (ranges >= msg.range_min) & (ranges <= msg.range_max)
    r, a = ranges[ok], angles[ok]
    points = np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros(len(r))])
    times = index[ok] * float(msg.time_increment) if msg.time_increment > 0 else np.empty(0)
    return points, times


def cloud_points(msg: Any, path: Path, topic: str) -> tuple[np.ndarray, np.ndarray]:
    """A PointCloud2's finite x, y, z (N, 3) metres and its per-point times, if any."""
    fields = {f.name: (FIELD_TYPES.get(int(f.datatype)), int(f.offset)) for f in msg.fields}
    if any(axis not in fields or fields[axis][0] is None for axis in "xyz"):
        raise InputError(f"{path}: {topic}: a PointCloud2 without x, y, z fields")
    order = ">" if msg.is_bigendian else "<"
    wanted = ["x", "y", "z"] + [f for f in TIME_FIELDS if f in fields][:1]
    dtype = np.dtype({"names": wanted, "formats": [order + fields[n][0] for n in wanted],
                      "offsets": [fields[n][1] for n in wanted],
                      "itemsize": int(msg.point_step)})
    count = int(msg.width) * int(msg.height)
    data = np.asarray(msg.data, dtype=np.uint8)
    if msg.row_step != msg.width * msg.point_step:  # padded rows: keep each row's points
        rows = data.reshape(int(msg.height), int(msg.row_step))[:, :msg.width * msg.point_step]
        data = np.ascontiguousarray(rows).reshape(-1)
    if data.size < count * msg.point_step:
        raise InputError(f"{path}: {topic}: a PointCloud2 holds {data.size} bytes for {count} "
                         f"{plural(count, 'point')} of {msg.point_step}")
    records = np.frombuffer(data[:count * msg.point_step].tobytes(), dtype=dtype, count=count)
    points = np.column_stack([records[a].astype(np.float64) for a in "xyz"])
    times = records[wanted[3]].astype(np.float64) if len(wanted) == 4 else np.empty(0)
    return points, times


def scan_frame(path: Path, topic: str | None = None) -> str:
    """The frame the recording's scans are in (their first message's ``header.frame_id``)."""
    with closing(topic_messages(path, SCANS, topic, None, "--scan-topic")) as messages:
        for _, _, msg in messages:
            return msg.header.frame_id
    raise InputError(f"{path}: {scan_topic(path, topic).name} holds no message")


def scan_times(path: Path, topic: str | None = None) -> np.ndarray:
    """The times of the recording's scans (seconds from its start), without reading their
    points' data into arrays."""
    return np.array([seconds for _, seconds, _ in
                     topic_messages(path, SCANS, topic, None, "--scan-topic", decode=False)],
                    dtype=np.float64)


def pose_track(path: Path, topic: str) -> tuple[np.ndarray, np.ndarray]:
    """A recording's nav_msgs/Odometry or geometry_msgs/PoseStamped topic: times (K,) seconds
    from its start and poses (K, 4, 4), the frame the messages name -> world."""
    times, poses = [], []
    for chosen, seconds, msg in topic_messages(path, (ODOMETRY, POSE), topic, None,
                                               "--pose-topic"):
        pose = msg.pose.pose if chosen.msgtype == ODOMETRY else msg.pose
        times.append(seconds)
        poses.append(pose_matrix(pose.position, pose.orientation))
    if not poses:
        raise InputError(f"{path}: {topic} holds no message")
    return np.array(times), np.array(poses)


def poses_at(times: np.ndarray, track_times: np.ndarray, track: np.ndarray) -> np.ndarray:
    """Poses (N, 4, 4) at ``times`` (seconds) interpolated along a pose track (linear in
    translation, spherical in rotation); held at its first and last pose outside it."""
    from scipy.spatial.transform import Rotation, Slerp

    order = np.argsort(track_times, kind="stable")
    track_times, track = track_times[order], track[order]
    t = np.clip(times, track_times[0], track_times[-1])
    out = np.tile(np.eye(4), (len(t), 1, 1))
    for axis in range(3):
        out[:, axis, 3] = np.interp(t, track_times, track[:, axis, 3])
    if len(track_times) == 1:
        out[:, :3, :3] = track[0, :3, :3]
        return out
    unique, first = np.unique(track_times, return_index=True)
    slerp = Slerp(unique, Rotation.from_matrix(track[first, :3, :3]))
    out[:, :3, :3] = slerp(t).as_matrix()
    return out


def pose_gaps(times: np.ndarray, track_times: np.ndarray) -> np.ndarray:
    """(N,) seconds from each of ``times`` to the nearest of ``track_times`` (K >= 1)."""
    track = np.sort(np.asarray(track_times, dtype=np.float64))
    times = np.asarray(times, dtype=np.float64)
    after = np.clip(np.searchsorted(track, times), 0, len(track) - 1)
    before = np.clip(after - 1, 0, len(track) - 1)
    return np.minimum(np.abs(times - track[before]), np.abs(track[after] - times))


def check_gaps(path: Path, source: str, times: np.ndarray, gaps: np.ndarray) -> None:
    """Refuse (InputError) scans at ``times`` (seconds from the recording's start) farther
    than :data:`GAP_MAX_S` from the nearest pose of ``source`` (``gaps``, seconds, from
    :func:`pose_gaps`); warn, with the gap, about those farther than :data:`GAP_WARN_S`."""
    far = gaps > GAP_WARN_S
    if not far.any():
        return
    worst = float(gaps.max())
    which = (f"{np.count_nonzero(far)} of {count(len(gaps), 'scan')} (recorded "
             f"{times[far].min():.1f} "
             f"to {times[far].max():.1f} s from its start) lie up to {worst:.1f} s from the "
             f"nearest pose of {source}")
    if worst > GAP_MAX_S:
        raise InputError(f"{path}: {which}, more than {GAP_MAX_S:g} s: their poses would be "
                         "guesses; give poses that cover the scans' time, or cut the "
                         "recording to the poses' time")
    warnings.warn(f"{path}: {which}, more than {GAP_WARN_S:g} s: they are placed at poses "
                  "held or interpolated across that gap", stacklevel=2)


def pose_matrix(position: Any, q: Any) -> np.ndarray:
    """A position and a unit quaternion (x, y, z; x, y, z, w: a geometry_msgs Pose's or
    Transform's) as a 4 x 4 matrix."""
    from scipy.spatial.transform import Rotation

    out = np.eye(4)
    out[:3, :3] = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_matrix()
    out[:3, 3] = [position.x, position.y, position.z]
    return out
