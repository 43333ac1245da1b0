"""ROS recordings (pcmapq.io.bags, bag_grids, bag_scans) written by rosbags' own writers in
every layout: their OccupancyGrid maps equal the maps they were made from, their scans and
odometry build the map the same files and pose file build, and a missing topic lists the
recording's topics."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pcmapq.core.cells import UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.core.grid import MetricGrid
from pcmapq.io import load_map
from pcmapq.io.bag_scans import poses_at
from pcmapq.io.bags import Message
from pcmapq.mapping import build_map_from_poses, open_scans, recorded_poses, scanner_poses
from testkit.paths import SAMPLE
from testkit.recordings import LAYOUTS, Cloud, Scan, write_recording


@pytest.fixture(scope="module")
def truth():
    return load_map(SAMPLE / "truth.yaml")


def name_of(layout: str) -> str:
    return {"ros1": "run.bag", "mcap": "run.mcap"}.get(layout, "run")


@pytest.mark.parametrize("layout", LAYOUTS)
def test_a_grid_reads_back_as_the_map_it_was_made_from(layout, truth, tmp_path):
    grid = MetricGrid(truth.grid.resolution, (1.5, -2.0, 0.4), truth.grid.shape)
    path = write_recording(tmp_path / name_of(layout), [(3.0, truth.state, grid)], layout)
    got = load_map(path)
    assert np.array_equal(got.state, truth.state)
    assert got.grid.resolution == truth.grid.resolution
    assert np.allclose(got.grid.origin, (1.5, -2.0, 0.4), atol=1e-12)


def test_the_last_grid_or_the_one_at_a_time_is_read(truth, tmp_path):
    """Recorded at 1 and 2 s of the bag's clock: 0 and 1 s from its start, the time axis of
    ``at``; each map names its message."""
    empty = np.full_like(truth.state, UNKNOWN)
    empty[:10, :10] = truth.state[:10, :10]
    path = write_recording(tmp_path / "run.mcap", [(1.0, empty, truth.grid),
                                                  (2.0, truth.state, truth.grid)], "mcap")
    last = load_map(path)
    assert np.array_equal(last.state, truth.state)
    assert last.message == Message("/map", 1, 1.0, 2.0)
    first = load_map(path, at=0.5)
    assert np.array_equal(first.state, empty) and first.message == Message("/map", 0, 0.0, 1.0)
    with pytest.raises(InputError, match="no OccupancyGrid at or before -0.5 s from the "
                                         "recording's start"):
        load_map(path, at=-0.5)


def test_a_missing_or_wrong_topic_lists_the_recordings_topics(truth, tmp_path):
    path = write_recording(tmp_path / "run.mcap", [(1.0, truth.state, truth.grid)], "mcap",
                           scans=[Scan(1.5, np.ones(5), 0.0, 0.1)])
    with pytest.raises(InputError) as err:
        load_map(path, topic="/global_map")
    assert str(err.value) == (f"{path}: no topic '/global_map' (--map-topic); topics: /map "
                              "(nav_msgs/msg/OccupancyGrid, 1), /scan "
                              "(sensor_msgs/msg/LaserScan, 1)")
    with pytest.raises(InputError, match="topic '/scan' is sensor_msgs/msg/LaserScan, not "
                                         "nav_msgs/OccupancyGrid"):
        load_map(path, topic="/scan")


def world_and_poses() -> tuple[np.ndarray, list[tuple[float, np.ndarray]]]:
    """Two walls (metres) and six sensor poses along a path, one a second."""
    rng = np.random.default_rng(0)
    world = np.vstack([
        np.column_stack([rng.uniform(-10, 10, 2000), np.full(2000, 5.0), rng.uniform(0, 2, 2000)]),
        np.column_stack([np.full(2000, 8.0), rng.uniform(-5, 5, 2000), rng.uniform(0, 2, 2000)])])
    poses = []
    for k in range(6):
        pose = np.eye(4)
        pose[:3, :3] = Rotation.from_euler("z", 5 * k, degrees=True).as_matrix()
        pose[:3, 3] = [0.5 * k, 0.2 * k, 0.0]
        poses.append((10.0 + k, pose))
    return world, poses


@pytest.mark.parametrize("layout", ["ros1", "ros2-sqlite", "mcap"])
def test_a_map_from_recorded_scans_and_odometry_is_the_files_map(layout, tmp_path):
    """The scans (PointCloud2, float32 as recorded) placed at the odometry build the same map
    as the same scans as .npy files at the same poses in a KITTI file, to 1e-9."""
    world, poses = world_and_poses()
    clouds = []
    folder = tmp_path / "scans"
    folder.mkdir()
    for k, (t, pose) in enumerate(poses):
        local = ((world - pose[:3, 3]) @ pose[:3, :3]).astype(np.float32).astype(np.float64)
        clouds.append(Cloud(t, local))
        np.save(folder / f"{k:02d}.npy", local)
    (tmp_path / "poses.txt").write_text("".join(
        " ".join(f"{v:.17g}" for v in pose[:3].ravel()) + "\n" for _, pose in poses))
    bag = write_recording(tmp_path / name_of(layout), [], layout, scans=clouds,
                          scan_topic="/points", poses=poses)
    from_bag = build_map_from_poses(open_scans(bag), recorded_poses(bag, None, "/odom")).points
    from_files = build_map_from_poses(open_scans(folder),
                                      scanner_poses(tmp_path / "poses.txt")).points
    assert from_bag.shape == from_files.shape
    assert np.abs(from_bag - from_files).max() < 1e-9


def test_laser_scans_are_their_returns_within_range(tmp_path):
    ranges = np.array([1.0, np.nan, 2.0, 50.0, 0.5])
    path = write_recording(tmp_path / "run.mcap", [], "mcap",
                           scans=[Scan(1.0, ranges, 0.0, np.pi / 2, range_max=30.0)])
    (points, times), = list(open_scans(path))
    assert len(points) == 3 and len(times) == 0  # NaN and 50 m (beyond 30 m) dropped
    assert np.allclose(points, [[1, 0, 0], [-2, 0, 0], [0.5, 0, 0]], atol=1e-6)


def test_poses_between_odometry_messages_are_interpolated():
    a, b = np.eye(4), np.eye(4)
    b[:3, :3] = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    b[:3, 3] = [2.0, 0.0, 0.0]
    got = poses_at(np.array([-1.0, 0.5, 2.0]), np.array([0.0, 1.0]), np.array([a, b]))
    assert np.allclose(got[0], a) and np.allclose(got[2], b)
    assert np.allclose(got[1, :3, 3], [1.0, 0.0, 0.0])
    assert Rotation.from_matrix(got[1, :3, :3]).as_euler("zyx", degrees=True)[0] == \
        pytest.approx(45.0)


def test_a_map_of_laser_scans_is_a_2d_cloud(tmp_path):
    """LaserScan scans placed by planar odometry make a flat map: scored as a 2D cloud, not
    through a 3D cloud's wall band (which would find no wall above its floor)."""
    from pcmapq.io.clouds import flat

    angles = np.linspace(-np.pi / 2, np.pi / 2, 91)
    scans, poses = [], []
    for k in range(4):
        pose = np.eye(4)
        pose[:2, 3] = [0.3 * k, 0.0]
        step = float(angles[1] - angles[0])
        scans.append(Scan(1.0 + k, np.full(91, 4.0), float(angles[0]), step))
        poses.append((1.0 + k, pose))
    path = write_recording(tmp_path / "run.mcap", [], "mcap", scans=scans, poses=poses)
    points = build_map_from_poses(open_scans(path), recorded_poses(path, None, "/odom")).points
    assert len(points) > 0 and flat(points)


@pytest.mark.parametrize("layout", ["ros2-sqlite", "mcap"])  # a ROS 1 bag: the real one
def test_poses_from_tf_compose_the_tree_up_to_its_root(layout, tmp_path):
    """Scans in frame ``laser``; /tf holds odom -> base (moving, one a second) and base ->
    laser (fixed, published once): each scan's pose is odom <- base at its time (between two
    transforms: interpolated) times base <- laser, and the map is the one those poses build."""
    world, poses = world_and_poses()
    mount = np.eye(4)
    mount[:3, 3] = [0.2, 0.0, 0.3]
    clouds, expected = [], []
    for t, pose in poses:
        scanner = pose @ mount
        local = ((world - scanner[:3, 3]) @ scanner[:3, :3]).astype(np.float32).astype(float)
        clouds.append(Cloud(t, local))
        expected.append(scanner)
    transforms = [(t, "odom", "base", pose) for t, pose in poses]
    transforms.append((poses[0][0], "base", "laser", mount))
    path = write_recording(tmp_path / name_of(layout), [], layout, scans=clouds,
                           scan_topic="/points", transforms=transforms)
    got = recorded_poses(path, None, "/tf")
    assert np.abs(got - np.array(expected)).max() < 1e-9
    with pytest.raises(InputError, match="no transform reaches frame 'camera'"):
        recorded_poses(path, None, "/tf", frame="camera")
