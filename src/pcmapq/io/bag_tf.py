"""A recording's transform tree (``/tf`` and ``/tf_static``, ``tf2_msgs/TFMessage``): the pose
of a frame (a scanner's) in the tree's root frame (``map`` or ``odom``) at given times, each
moving link interpolated at them (:func:`~pcmapq.io.bag_scans.poses_at`), a static link held.
Frame names are compared without a leading ``/`` (ROS 1 wrote ``/base_laser``). Times are
seconds of the recording's clock; metres."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.io.bag_scans import pose_matrix, poses_at
from pcmapq.io.bags import deserialised, opened

#: The transform messages' type.
TF = "tf2_msgs/msg/TFMessage"
#: Longest chain of frames followed to the root.
MAX_DEPTH = 64


def links(path: Path) -> dict[str, tuple[str, np.ndarray, np.ndarray]]:
    """Every frame's link to its parent: child -> (parent, times (K,), poses (K, 4, 4) of the
    child in the parent's frame), from every TFMessage topic of the recording."""
    found: dict[str, tuple[str, list[float], list[np.ndarray]]] = {}
    with opened(path) as reader:
        connections = [c for c in reader.connections if c.msgtype == TF]
        if not connections:
            raise InputError(f"{path}: no tf2_msgs/TFMessage topic (/tf, /tf_static)")
        for connection, stamp, raw in reader.messages(connections=connections):
            for t in deserialised(reader, raw, connection, path).transforms:
                child, parent = _name(t.child_frame_id), _name(t.header.frame_id)
                entry = found.setdefault(child, (parent, [], []))
                if entry[0] != parent:
                    raise InputError(f"{path}: frame {child!r} has two parents, {entry[0]!r} "
                                     f"and {parent!r}")
                entry[1].append(stamp / 1e9)
                entry[2].append(pose_matrix(t.transform.translation, t.transform.rotation))
    return {c: (p, np.array(ts), np.array(ms)) for c, (p, ts, ms) in found.items()}


def frame_poses(path: Path, frame: str, times: np.ndarray) -> np.ndarray:
    """The pose (N, 4, 4) of ``frame`` in the tree's root frame at each of ``times``."""
    tree = links(path)
    frame = _name(frame)
    if frame not in tree:
        raise InputError(f"{path}: no transform reaches frame {frame!r} (--frame); frames: "
                         f"{', '.join(sorted(tree))}")
    out = np.tile(np.eye(4), (len(times), 1, 1))
    node = frame
    for _ in range(MAX_DEPTH):
        if node not in tree:
            return out
        parent, track_times, track = tree[node]
        out = poses_at(times, track_times, track) @ out
        node = parent
    raise InputError(f"{path}: the transforms above frame {frame!r} form a loop")


def _name(frame: str) -> str:
    return frame.lstrip("/")
