"""A SLAM run as ``pcmapq track`` reads it: the scans, one estimated pose each, and the map of
the first k scans, grown scan by scan.

- a CARMEN log (:class:`LaserRun`): its laser endpoints at its ``FLASER`` poses, or at the
  poses of a file given instead; a map of the first k scans is a prefix of the endpoints.
- a scan sequence (:class:`ScanRun`): a folder of scans, a ROS bag or an MCAP file, placed at
  given poses or at KISS-ICP's; the map grows in a voxel map (centroids of 0.1 m cells, as
  ``pcmapq map``), one scan at a time.

Each map carries the area its scans saw (their views,
:func:`~pcmapq.raster.footprint.view_outlines`, in the poses' x, y: a 3D map's levelling is not
applied to them), filled once as the map grows (:mod:`~pcmapq.raster.seen`), so it is scored
inside it (footprint rule ``seen``). A laser's views reach no farther than its readings draw a
wall: only the readings within twice the wall image's closing of their neighbours on both sides
make them (:func:`~pcmapq.raster.footprint.joined_readings`); a 3D scanner's, whose readings
lie a few tenths of a degree apart in bearing, are not cut.

Poses are (K, 4, 4) in the map's world frame, ``p_world = pose_k @ p_scanner``; metres.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.transform import affine
from pcmapq.core.words import plural
from pcmapq.features.walls import CLOSING
from pcmapq.io import PointMap
from pcmapq.io.bag_scans import scan_times
from pcmapq.io.bags import is_bag
from pcmapq.io.carmen import (
    DEFAULT_MAX_RANGE,
    LaserScans,
    endpoint_scans,
    endpoints,
    is_carmen,
    read_laser_scans,
)
from pcmapq.mapping import (
    ScanGrid,
    ScanSequence,
    VoxelMap,
    build_map_kiss,
    open_scans,
    recorded_poses,
    scanner_poses,
)
from pcmapq.mapping.reference import scans_for_poses
from pcmapq.raster.footprint import view_outlines
from pcmapq.raster.seen import NO_VIEW, add_views, scan_views

#: Cell of the voxel map a scan sequence grows into, metres (``pcmapq map``'s default).
SCAN_VOXEL = 0.1
#: Scanner readings kept, metres from the scanner (KISS-ICP's defaults).
MIN_RANGE, MAX_RANGE = 0.0, 100.0


def planar_poses(xyt: np.ndarray) -> np.ndarray:
    """(K, 4, 4) poses of planar poses (K, 3): x, y metres, theta radians."""
    xyt = np.asarray(xyt, dtype=np.float64).reshape(-1, 3)
    c, s = np.cos(xyt[:, 2]), np.sin(xyt[:, 2])
    poses = np.tile(np.eye(4), (len(xyt), 1, 1))
    poses[:, 0, 0], poses[:, 0, 1], poses[:, 1, 0], poses[:, 1, 1] = c, -s, s, c
    poses[:, :2, 3] = xyt[:, :2]
    return poses


def planar_of(poses: np.ndarray) -> np.ndarray:
    """(K, 3) x, y (metres) and yaw (radians) of poses (K, 4, 4)."""
    return np.column_stack([poses[:, 0, 3], poses[:, 1, 3],
                            np.arctan2(poses[:, 1, 0], poses[:, 0, 0])])


@dataclass(frozen=True)
class LaserRun:
    """A CARMEN log's scans at ``poses`` (K, 4, 4; the log's own or a file's), readings up to
    ``max_range`` metres; ``stamps`` (K,) seconds of the log's clock; ``poses_source``: where
    the poses come from, in words."""

    path: Path
    scans: LaserScans
    poses: np.ndarray
    stamps: np.ndarray | None
    max_range: float = DEFAULT_MAX_RANGE
    poses_source: str = "the log's own FLASER poses"

    def __len__(self) -> int:
        return len(self.poses)

    @property
    def time_origin(self) -> float:
        """Time 0 of the run's steps, seconds of the log's clock: its first scan's."""
        return 0.0 if self.stamps is None else float(self.stamps[0])

    def maps(self, ends: Sequence[int],
             tick: Callable[[int], None] = lambda done: None) -> Iterator[PointMap]:
        """The 2D map of the first ``end`` scans for each of ``ends`` (increasing)."""
        return (m for m, _ in self.steps(ends, tick))

    def steps(self, ends: Sequence[int], tick: Callable[[int], None] = lambda done: None
              ) -> Iterator[tuple[PointMap, np.ndarray]]:
        """For each of ``ends`` (increasing): the 2D map of the first ``end`` scans, and the
        readings (N, 3; z = 0) of the scans since the step before. Every endpoint is computed
        once, and each map is a prefix of them."""
        xy = endpoints(planar_of(self.poses), self.scans.ranges, self.scans.angles,
                       self.max_range)
        scan = endpoint_scans(planar_of(self.poses), self.scans.ranges, self.scans.angles,
                              self.max_range)
        offsets = np.concatenate([[0], np.cumsum(np.bincount(scan, minlength=len(self)))])
        views = scan_views(self.poses[:, :2, 3], xy, scan, 2 * CLOSING)
        points = np.column_stack([xy, np.zeros(len(xy))])
        before, seen = 0, NO_VIEW
        for end in ends:
            tick(int(end))
            seen = add_views(seen, views[before:end])
            yield (PointMap(self.path, points[:offsets[end]], is_3d=False, kind="carmen",
                            seen=seen), points[offsets[before]:offsets[end]])
            before = end


@dataclass(frozen=True)
class ScanRun:
    """A scan sequence at ``poses`` (K, 4, 4), grown into a voxel map of ``voxel`` metres;
    ``stamps`` (K,): a recording's scan times, seconds from its start (None: a folder's
    scans); ``poses_source``: where the poses come from, in words."""

    path: Path
    sequence: ScanSequence
    poses: np.ndarray
    stamps: np.ndarray | None = None
    voxel: float = SCAN_VOXEL
    poses_source: str = ""

    def __len__(self) -> int:
        return len(self.poses)

    @property
    def time_origin(self) -> float:
        """Time 0 of the run's steps: the recording's start (its stamps are seconds from it)."""
        return 0.0

    def maps(self, ends: Sequence[int],
             tick: Callable[[int], None] = lambda done: None) -> Iterator[PointMap]:
        """The 3D map of the first ``end`` scans for each of ``ends`` (increasing)."""
        return (m for m, _ in self.steps(ends, tick))

    def steps(self, ends: Sequence[int], tick: Callable[[int], None] = lambda done: None
              ) -> Iterator[tuple[PointMap, np.ndarray]]:
        """For each of ``ends`` (increasing): the 3D map of the first ``end`` scans, and the
        scans since the step before (N, 3; their own voxel map's points). Each scan is placed
        and added to the voxel maps once."""
        grid, wanted, views, seen = ScanGrid(self.voxel), list(ends), [], NO_VIEW
        recent = VoxelMap(self.voxel)
        for index, (points, _) in enumerate(self.sequence):
            ranges = np.linalg.norm(points, axis=1)
            points = points[(ranges >= MIN_RANGE) & (ranges <= MAX_RANGE)]
            pose = self.poses[index]
            placed = affine(points, pose)
            grid.add(placed, index)
            recent.add(placed)
            views.append(view_outlines(pose[None, :2, 3], placed[:, :2],
                                       np.zeros(len(placed), dtype=np.int64))[0])
            tick(index + 1)
            if wanted and index + 1 == wanted[0]:
                wanted.pop(0)
                seen, views = add_views(seen, np.stack(views)), []
                built = grid.map()
                yield (PointMap.of_scans(self.path, built.points, built.scan, seen),
                       recent.points())
                recent = VoxelMap(self.voxel)
            if not wanted:
                return


Run = LaserRun | ScanRun


def open_run(source: Path, poses: Path | None = None, *,
             progress: Callable[[int, int], None] | None = None,
             scan_topic: str | None = None, pose_topic: str | None = None,
             frame: str | None = None) -> Run:
    """The run at ``source`` (a CARMEN log, or scans) with the poses of ``poses`` (a KITTI or
    TUM file, one pose per scan, the scanner's: a warning when they move as a camera's, see
    :func:`~pcmapq.mapping.scanner_poses`), or of a recording's ``pose_topic`` at its scans'
    times, else the log's own, else KISS-ICP's (``progress(done, total)`` while it runs); a
    recording's scans are its ``scan_topic``'s, timed from its start. InputError, one line,
    when the counts differ."""
    estimate = (scanner_poses(poses) if poses is not None else
                recorded_poses(source, scan_topic, pose_topic, frame=frame)
                if pose_topic is not None
                else None)
    if is_carmen(source):
        scans = read_laser_scans(source)
        if estimate is None:
            estimate = planar_poses(scans.poses)
        elif len(estimate) != len(scans.poses):
            raise InputError(f"{poses}: {len(estimate)} {plural(len(estimate), 'pose')} for the "
                             f"{len(scans.poses)} {plural(len(scans.poses), 'scan')} of {source} "
                             "(one pose per scan)")
        return LaserRun(source, scans, estimate, scans.stamps,
                        **({} if poses is None else {"poses_source": str(poses)}))
    sequence = open_scans(source, topic=scan_topic)
    if estimate is None:
        _, estimate = build_map_kiss(source, progress=progress, topic=scan_topic)
    sequence = scans_for_poses(sequence, len(estimate), poses_path=poses or pose_topic)
    stamps = scan_times(source, scan_topic)[:len(sequence)] if is_bag(source) else None
    return ScanRun(source, sequence, estimate, stamps,
                   poses_source=str(poses) if poses is not None else
                   f"{pose_topic} of {source}" if pose_topic is not None else "KISS-ICP's poses")


def reference_poses_of(path: Path, count: int, calib: Path | None = None) -> np.ndarray:
    """Reference poses (count, 4, 4) from a KITTI or TUM file (with ``calib``, moved into the
    scanner's frame: see :func:`~pcmapq.mapping.scanner_poses`), or a CARMEN log's FLASER
    poses; InputError, one line, when there are not ``count`` of them (one per scan)."""
    poses = (planar_poses(read_laser_scans(path).poses) if is_carmen(path)
             else scanner_poses(path, calib))
    if len(poses) != count:
        raise InputError(f"{path}: {len(poses)} reference {plural(len(poses), 'pose')} for "
                         f"{count} {plural(count, 'scan')} (one per scan)")
    return poses
