"""Recordings other software writes that rosbags does not read as they are: ROS 1's older
``tf/tfMessage`` transforms (read as tf2's, the same layout), ROS 1 bags of an old format or
with index records rosbags refuses (one line saying which and how to convert), and a storage
file compressed whole with zstd (``.mcap.zstd``: read)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io import load_map
from pcmapq.io.bag_files import zstd_module
from pcmapq.io.bags import Message
from pcmapq.mapping import recorded_poses
from testkit.paths import SAMPLE
from testkit.recordings import Cloud, write_recording


@pytest.fixture(scope="module")
def truth():
    return load_map(SAMPLE / "truth.yaml")


@pytest.fixture(scope="module")
def ros1_bag(truth, tmp_path_factory) -> bytes:
    """A ROS 1 bag (V2.0, rosbags' writer) of one map, as bytes."""
    path = tmp_path_factory.mktemp("bag") / "run.bag"
    return write_recording(path, [(1.0, truth.state, truth.grid)], "ros1").read_bytes()


def test_ros1_transforms_of_the_older_tf_type_are_read_as_tf2s(tmp_path: Path) -> None:
    """/tf of type tf/tfMessage (older ROS 1 drivers): the scans' poses come from it."""
    points = np.random.default_rng(0).uniform(-3, 3, (50, 3))
    moves = [np.eye(4) for _ in range(3)]
    for k, pose in enumerate(moves):
        pose[:3, 3] = [0.5 * k, 0.1 * k, 0.0]
    path = write_recording(tmp_path / "run.bag", [], "ros1",
                           scans=[Cloud(1.0 + k, points) for k in range(3)],
                           scan_topic="/points", tf_type="tf/msg/tfMessage",
                           transforms=[(1.0 + k, "odom", "laser", pose)
                                       for k, pose in enumerate(moves)])
    assert np.abs(recorded_poses(path, None, "/tf") - np.array(moves)).max() < 1e-12


def test_a_ros1_bag_of_format_1_2_is_refused_saying_how_to_convert_it(
        ros1_bag: bytes, tmp_path: Path) -> None:
    path = tmp_path / "old.bag"
    path.write_bytes(b"#ROSRECORD V1.2\n" + ros1_bag[len(b"#ROSBAG V2.0\n"):])
    with pytest.raises(InputError) as err:
        load_map(path)
    assert str(err.value) == (
        f"{path}: a ROS 1 bag of format V1.2 (ROS 0.5 to 1.0), which rosbags does not read: "
        f"convert it to V2.0 with ROS 1's 'rosbag reindex {path}' (it keeps the original "
        "beside it as .orig.bag)")


def test_a_ros1_bag_with_index_records_rosbags_refuses_says_how_to_rebuild_them(
        ros1_bag: bytes, tmp_path: Path) -> None:
    """An index record (op 4) with a field rosbags does not know: rosbags asserts."""
    at = ros1_bag.find(b"count=", ros1_bag.find(b"op=\x04"))
    path = tmp_path / "old.bag"
    path.write_bytes(ros1_bag[:at + 2] + b"x" + ros1_bag[at + 3:])  # count= -> coxnt=
    with pytest.raises(InputError) as err:
        load_map(path)
    assert str(err.value) == (
        f"{path}: a ROS 1 bag (V2.0) whose index rosbags cannot read (index records of an "
        f"older rosbag, none, or damaged); rebuild its index with ROS 1's 'rosbag reindex "
        f"{path}'")


@pytest.mark.parametrize("suffix", [".mcap.zstd", ".mcap.zst"])
def test_a_zstd_compressed_mcap_reads_as_the_mcap(truth, tmp_path: Path, suffix: str) -> None:
    zstd = zstd_module()
    mcap = write_recording(tmp_path / "run.mcap", [(1.0, truth.state, truth.grid)], "mcap")
    path = tmp_path / f"run{suffix}"
    packed = zstd.compress(mcap.read_bytes())
    path.write_bytes(packed)
    got = load_map(path)
    assert np.array_equal(got.state, truth.state)
    assert got.message == Message("/map", 0, 0.0, 1.0)
    assert path.read_bytes() == packed  # the input is not modified
    cut = tmp_path / f"cut{suffix}"
    cut.write_bytes(packed[:len(packed) // 2])
    with pytest.raises(InputError, match=f"^{cut}: not a readable zstd-compressed recording: "):
        load_map(cut)
