"""Small ROS recordings written with rosbags' own writers, for tests and the validation: a
sequence of ``nav_msgs/OccupancyGrid`` maps (and optionally ``sensor_msgs/LaserScan`` scans)
as a ROS 1 bag, a ROS 2 bag (SQLite or MCAP storage) or its storage file alone. Grids are
occupancy maps (:class:`~pcmapq.io.occupancy.OccupancyMap` states) with their metric grids;
times are seconds of the bag's clock."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.cells import FREE, OCCUPIED
from pcmapq.core.grid import MetricGrid

#: The layouts a recording can be written in.
LAYOUTS = ("ros1", "ros2-sqlite", "ros2-mcap", "mcap")


@dataclass(frozen=True)
class Scan:
    """A planar laser scan at ``time_s``: ranges (N,) metres from ``angle_min`` by
    ``increment`` radians (NaN: no return)."""

    time_s: float
    ranges: np.ndarray
    angle_min: float
    increment: float
    range_max: float = 30.0


@dataclass(frozen=True)
class Cloud:
    """A point cloud scan at ``time_s``: points (N, 3) metres in the sensor frame (written as
    float32 x, y, z) and per-point times (N,) seconds (a float32 field ``t``; None: none)."""

    time_s: float
    points: np.ndarray
    times: np.ndarray | None = None


def grid_values(state: np.ndarray) -> np.ndarray:
    """An occupancy state (rows, cols; row 0 the top) as OccupancyGrid data: 100 occupied, 0
    free, -1 unknown, rows from the bottom (the grid's origin), flattened."""
    values = np.full(state.shape, -1, dtype=np.int8)
    values[state == OCCUPIED] = 100
    values[state == FREE] = 0
    return np.flipud(values).ravel()


def write_recording(path: Path, maps: Sequence[tuple[float, np.ndarray, MetricGrid]],
                    layout: str = "ros2-mcap", scans: Sequence[Scan | Cloud] = (),
                    map_topic: str = "/map", scan_topic: str = "/scan",
                    poses: Sequence[tuple[float, np.ndarray]] = (),
                    pose_topic: str = "/odom", compress: bool = False,
                    transforms: Sequence[tuple[float, str, str, np.ndarray]] = (),
                    tf_type: str = "tf2_msgs/msg/TFMessage") -> Path:
    """Write ``maps`` ((seconds, state, grid) each) on ``map_topic`` and ``scans`` on
    ``scan_topic`` and ``poses`` ((seconds, 4 x 4 pose) each) as nav_msgs/Odometry on
    ``pose_topic`` as a recording of ``layout`` (:data:`LAYOUTS`; ``mcap``: the ROS 2 MCAP
    file alone) at ``path`` (a ``.bag`` file, a ROS 2 bag folder, or an ``.mcap`` file). The
    path written. ``compress``: a ROS 2 recording's messages zstd-compressed. ``transforms``:
    (seconds, parent, child, 4 x 4 pose of the child in the parent) each, on ``/tf`` as
    ``tf_type`` (ROS 1's older ``tf/msg/tfMessage`` has tf2's layout); scans are in the frame
    ``laser``."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ros1 = layout == "ros1"
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if tf_type not in store.types:
        store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms",
                                          tf_type))
    folder = path.with_suffix("") if layout == "mcap" else path
    messages = sorted([(t, map_topic, _grid(store, t, state, grid, ros1))
                       for t, state, grid in maps] +
                      [(s.time_s, scan_topic, _scan(store, s, ros1) if isinstance(s, Scan)
                        else _cloud(store, s, ros1)) for s in scans] +
                      [(t, pose_topic, _odometry(store, t, pose, ros1)) for t, pose in poses] +
                      [(t, "/tf", _tf(store, t, parent, child, pose, ros1, tf_type))
                       for t, parent, child, pose in transforms],
                      key=lambda m: (m[0], m[1]))
    clouds = any(isinstance(s, Cloud) for s in scans)
    kinds = {map_topic: "nav_msgs/msg/OccupancyGrid", pose_topic: "nav_msgs/msg/Odometry",
             "/tf": tf_type,
             scan_topic: "sensor_msgs/msg/PointCloud2" if clouds else "sensor_msgs/msg/LaserScan"}
    used = {topic for _, topic, _ in messages}
    if ros1:
        from rosbags.rosbag1 import Writer as Writer1

        with Writer1(path) as writer:
            conns = {topic: writer.add_connection(topic, kinds[topic], typestore=store)
                     for topic in sorted(used)}
            for t, topic, msg in messages:
                writer.write(conns[topic], _ns(t), store.serialize_ros1(msg, kinds[topic]))
        return path
    from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

    plugin = StoragePlugin.SQLITE3 if layout == "ros2-sqlite" else StoragePlugin.MCAP
    writer = Writer(folder, version=9, storage_plugin=plugin)
    if compress:
        writer.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    with writer:
        conns = {topic: writer.add_connection(topic, kinds[topic], typestore=store)
                 for topic in sorted(used)}
        for t, topic, msg in messages:
            writer.write(conns[topic], _ns(t), store.serialize_cdr(msg, kinds[topic]))
    if layout == "mcap":
        (folder / f"{folder.name}.mcap").rename(path)
        for leftover in folder.iterdir():
            leftover.unlink()
        folder.rmdir()
    return path


def _ns(t: float) -> int:
    return int(round(t * 1e9))


def _header(store, t: float, frame: str, ros1: bool):
    stamp = store.types["builtin_interfaces/msg/Time"](sec=int(math.floor(t)),
                                                       nanosec=int(round((t % 1) * 1e9)))
    header = store.types["std_msgs/msg/Header"]
    return header(seq=0, stamp=stamp, frame_id=frame) if ros1 else \
        header(stamp=stamp, frame_id=frame)


def _grid(store, t: float, state: np.ndarray, grid: MetricGrid, ros1: bool):
    types = store.types
    x, y, yaw = grid.origin
    pose = types["geometry_msgs/msg/Pose"](
        position=types["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0),
        orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2),
                                                          w=math.cos(yaw / 2)))
    rows, cols = state.shape
    info = types["nav_msgs/msg/MapMetaData"](
        map_load_time=_header(store, t, "map", ros1).stamp, resolution=float(grid.resolution),
        width=cols, height=rows, origin=pose)
    return types["nav_msgs/msg/OccupancyGrid"](header=_header(store, t, "map", ros1), info=info,
                                               data=grid_values(state))


def _scan(store, scan: Scan, ros1: bool):
    n = len(scan.ranges)
    return store.types["sensor_msgs/msg/LaserScan"](
        header=_header(store, scan.time_s, "laser", ros1), angle_min=float(scan.angle_min),
        angle_max=float(scan.angle_min + (n - 1) * scan.increment),
        angle_increment=float(scan.increment), time_increment=0.0, scan_time=0.0,
        range_min=0.0, range_max=float(scan.range_max),
        ranges=np.asarray(scan.ranges, dtype=np.float32),
        intensities=np.zeros(0, dtype=np.float32))


def _cloud(store, cloud: Cloud, ros1: bool):
    types = store.types
    field = types["sensor_msgs/msg/PointField"]
    names = ["x", "y", "z"] + ([] if cloud.times is None else ["t"])
    fields = [field(name=n, offset=4 * i, datatype=7, count=1) for i, n in enumerate(names)]
    columns = [cloud.points[:, 0], cloud.points[:, 1], cloud.points[:, 2]]
    if cloud.times is not None:
        columns.append(cloud.times)
    data = np.column_stack(columns).astype("<f4")
    n = len(data)
    return types["sensor_msgs/msg/PointCloud2"](
        header=_header(store, cloud.time_s, "laser", ros1), height=1, width=n, fields=fields,
        is_bigendian=False, point_step=4 * len(names), row_step=4 * len(names) * n,
        data=data.view(np.uint8).ravel(), is_dense=True)


def _odometry(store, t: float, pose: np.ndarray, ros1: bool):
    from scipy.spatial.transform import Rotation

    types = store.types
    x, y, z, w = Rotation.from_matrix(pose[:3, :3]).as_quat()
    msg_pose = types["geometry_msgs/msg/Pose"](
        position=types["geometry_msgs/msg/Point"](x=float(pose[0, 3]), y=float(pose[1, 3]),
                                                  z=float(pose[2, 3])),
        orientation=types["geometry_msgs/msg/Quaternion"](x=float(x), y=float(y), z=float(z),
                                                          w=float(w)))
    covariance = np.zeros(36)
    twist = types["geometry_msgs/msg/Twist"](
        linear=types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
        angular=types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0))
    return types["nav_msgs/msg/Odometry"](
        header=_header(store, t, "odom", ros1), child_frame_id="lidar",
        pose=types["geometry_msgs/msg/PoseWithCovariance"](pose=msg_pose, covariance=covariance),
        twist=types["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=covariance))


def _tf(store, t: float, parent: str, child: str, pose: np.ndarray, ros1: bool,
        tf_type: str):
    from scipy.spatial.transform import Rotation

    types = store.types
    x, y, z, w = Rotation.from_matrix(pose[:3, :3]).as_quat()
    header = _header(store, t, parent, ros1)
    transform = types["geometry_msgs/msg/Transform"](
        translation=types["geometry_msgs/msg/Vector3"](x=float(pose[0, 3]), y=float(pose[1, 3]),
                                                       z=float(pose[2, 3])),
        rotation=types["geometry_msgs/msg/Quaternion"](x=float(x), y=float(y), z=float(z),
                                                       w=float(w)))
    stamped = types["geometry_msgs/msg/TransformStamped"](header=header, child_frame_id=child,
                                                          transform=transform)
    return types[tf_type](transforms=[stamped])
