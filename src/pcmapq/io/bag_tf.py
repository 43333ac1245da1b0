"""A recording's transform tree (``/tf`` and ``/tf_static``: ``tf2_msgs/TFMessage``, or ROS 1's
older ``tf/tfMessage`` of the same layout): the pose of a frame (a scanner's) in the tree's
root frame (``map`` or ``odom``) at given times, each moving link interpolated at them
(:func:`~pcmapq.io.bag_scans.poses_at`), a static link held. A link is static when it comes
from ``/tf_static`` or holds one transform; a moving link checks how far in time the scans lie
from its transforms (:func:`~pcmapq.io.bag_scans.check_gaps`). Frame names are compared without
a leading ``/`` (ROS 1 wrote ``/base_laser``). Times are seconds from the recording's start;
metres."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.io.bag_scans import check_gaps, pose_gaps, pose_matrix, poses_at
from pcmapq.io.bags import deserialised, messages, opened, seconds

#: The transform messages' types: ROS 2's and ROS 1's tf2, and ROS 1's older tf (same layout).
TF_TYPES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")
#: The transform messages' type, as named in messages.
TF = TF_TYPES[0]
#: Longest chain of frames followed to the root.
MAX_DEPTH = 64


@dataclass(frozen=True)
class Link:
    """A frame's link to its parent: times (K,) seconds from the recording's start and poses
    (K, 4, 4) of the child in the parent's frame; ``static`` when from ``/tf_static``."""

    parent: str
    times: np.ndarray
    poses: np.ndarray
    static: bool

    @property
    def moving(self) -> bool:
        return not self.static and len(self.times) > 1


def links(path: Path) -> dict[str, Link]:
    """Every frame's link to its parent, by child frame, from every transform topic of the
    recording."""
    found: dict[str, tuple[str, list[float], list[np.ndarray], bool]] = {}
    with opened(path) as reader:
        connections = [c for c in reader.connections if c.msgtype in TF_TYPES]
        if not connections:
            raise InputError(f"{path}: no tf2_msgs/TFMessage or tf/tfMessage topic (/tf, "
                             "/tf_static)")
        for connection, stamp, raw in messages(reader, connections, path):
            for t in deserialised(reader, raw, connection, path).transforms:
                child, parent = _name(t.child_frame_id), _name(t.header.frame_id)
                entry = found.setdefault(child, (parent, [], [],
                                                 connection.topic == "/tf_static"))
                if entry[0] != parent:
                    raise InputError(f"{path}: frame {child!r} has two parents, {entry[0]!r} "
                                     f"and {parent!r}")
                entry[1].append(seconds(reader, stamp))
                entry[2].append(pose_matrix(t.transform.translation, t.transform.rotation))
    return {c: Link(p, np.array(ts), np.array(ms), static)
            for c, (p, ts, ms, static) in found.items()}


def frame_poses(path: Path, frame: str, times: np.ndarray) -> np.ndarray:
    """The pose (N, 4, 4) of ``frame`` in the tree's root frame at each of ``times``."""
    tree = links(path)
    frame = _name(frame)
    if frame not in tree:
        raise InputError(f"{path}: no transform reaches frame {frame!r} (--frame); frames: "
                         f"{', '.join(sorted(tree))}")
    out = np.tile(np.eye(4), (len(times), 1, 1))
    gaps, moving = np.zeros(len(times)), []
    node = frame
    for _ in range(MAX_DEPTH):
        if node not in tree:
            if moving:
                check_gaps(path, f"/tf ({', '.join(moving)})", times, gaps)
            return out
        link = tree[node]
        if link.moving:
            gaps = np.maximum(gaps, pose_gaps(times, link.times))
            moving.append(f"{link.parent} -> {node}")
        out = poses_at(times, link.times, link.poses) @ out
        node = link.parent
    raise InputError(f"{path}: the transforms above frame {frame!r} form a loop")


def _name(frame: str) -> str:
    return frame.lstrip("/")
