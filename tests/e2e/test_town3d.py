"""A town of alike blocks (testkit.town3d, 3 x 3): the global 3D search's features match too
few right pairs there and its guess is upside down; the plans' second guess registers it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import open3d as o3d
import pytest

from pcmapq.align.features3d import global_registration
from pcmapq.core.voxels import voxel_centroids
from testkit.command import run
from testkit.paths import shared
from testkit.poses import errors
from testkit.town3d import map_to_truth, pair

#: Points a cloud: few enough for a test, dense enough that every surface has its points.
POINTS = 200_000
#: The registration's working voxel (pcmapq's default --voxel-3d), metres.
VOXEL = 0.3


@pytest.fixture(scope="module")
def clouds() -> tuple[np.ndarray, np.ndarray]:
    """The 3 x 3 town's map and truth, (POINTS, 3) float32 each."""
    return pair(POINTS, 3, 3)


@pytest.fixture(scope="module")
def town(clouds: tuple[np.ndarray, np.ndarray],
         tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    out = tmp_path_factory.mktemp("town")
    paths = out / "map.ply", out / "truth.ply"
    for path, points in zip(paths, clouds, strict=True):
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points.astype(np.float64)))
        o3d.io.write_point_cloud(str(path), cloud)
    return paths


def test_the_features_alone_turn_the_town_upside_down(
        clouds: tuple[np.ndarray, np.ndarray]) -> None:
    """What the second guess is for: the features' guess on this town is far from the truth."""
    source, target = (voxel_centroids(c - c.mean(axis=0), VOXEL) for c in clouds)
    guess = global_registration(source, target, VOXEL)
    assert guess[2, 2] < 0.0 or abs(np.degrees(np.arctan2(guess[1, 0], guess[0, 0])) + 25) > 5


def test_the_town_is_registered_and_scored(town: tuple[Path, Path], tmp_path: Path) -> None:
    out = tmp_path / "out.json"
    got = run("eval", str(town[0]), str(town[1]), "--no-noref", "--no-structures", "--json",
              str(out))
    assert got.returncode == 0, got.stderr
    doc = json.loads(out.read_text())
    found = np.array(doc["frames"]["registration_3d"])
    # The map's drift (0.15 m down, 0.1 m sideways at its far end) bends it: no rigid pose
    # fits it exactly.
    shift, angle = errors(found, map_to_truth())
    assert shift < 0.1 and angle < 0.2
    assert doc["alignment_3d"]["fitness"] > 0.9


def test_a_scan_of_another_place_is_still_refused(town: tuple[Path, Path]) -> None:
    """A real LiDAR scan against the town: neither guess fits it, and the map is refused in
    one line, not scored."""
    scan = shared("registration", "source.ply")
    got = run("eval", str(scan), str(town[1]), "--no-noref", "--no-structures")
    assert got.returncode == 1
    assert "does not seem to show the place of" in got.stderr
    assert len(got.stderr.strip().splitlines()) == 1
