"""The wall band of a 3D cloud: levelling, floor height, and which points come out."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from pcmapq.raster import slice as slice_module
from pcmapq.raster.levelling import level_rotation
from pcmapq.raster.slice import floor_height, wall_band
from testkit import synth

FLOOR_Z = 1.7
TILT_DEG = 5.0
WALL_HEIGHT = 2.6  # synth.lidar_cloud's default


def rot_x(degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[1.0, 0.0, 0.0], [0.0, np.cos(a), -np.sin(a)], [0.0, np.sin(a), np.cos(a)]])


def angle_deg(r: np.ndarray) -> float:
    """The rotation angle of a 3x3 rotation, degrees."""
    return float(np.degrees(np.arccos(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0))))


@pytest.fixture(scope="module")
def plan() -> np.ndarray:
    return synth.building_plan(0)


@pytest.fixture(scope="module")
def cloud(plan: np.ndarray) -> np.ndarray:
    """The synthetic building, plan frame, floor at z = 0."""
    return synth.lidar_cloud(plan)


@pytest.fixture(scope="module")
def tilted(cloud: np.ndarray) -> np.ndarray:
    """The building raised to a floor at FLOOR_Z, then tilted TILT_DEG about x: levelling it
    gives back the plan's x, y with the floor at FLOOR_Z."""
    return (cloud + [0.0, 0.0, FLOOR_Z]) @ rot_x(TILT_DEG).T


@pytest.fixture(scope="module")
def walls(plan: np.ndarray) -> cKDTree:
    return cKDTree(synth.wall_points(plan, spacing=0.01))


def test_level_rotation_undoes_the_tilt(tilted: np.ndarray) -> None:
    r = level_rotation(tilted)
    assert angle_deg(r @ rot_x(TILT_DEG)) < 0.1
    assert abs(r[0, 1] - r[1, 0]) < 1e-9  # no yaw: rotation about the horizontal axis only


@pytest.mark.parametrize("step", [2, 5, 7])
def test_level_rotation_of_thinned_copies_is_the_tilt(tilted: np.ndarray, step: int) -> None:
    """Every step-th point, in another order too: the sample RANSAC searches differs, and its
    plane can be a fraction of a degree off the floor (up to 0.8 on such copies); the voxels
    within reach of it, fitted again until they stop changing, give the floor's own tilt."""
    thinned = tilted[::step]
    for points in (thinned, thinned[np.random.default_rng(step).permutation(len(thinned))]):
        assert angle_deg(level_rotation(points) @ rot_x(TILT_DEG)) < 0.02


def test_floor_height(tilted: np.ndarray) -> None:
    levelled = tilted @ level_rotation(tilted).T
    assert floor_height(levelled) == pytest.approx(FLOOR_Z, abs=0.02)


def test_wall_band_is_walls_only(tilted: np.ndarray, cloud: np.ndarray, walls: cKDTree) -> None:
    band, levelling = wall_band(tilted, 0.3, 2.0)
    assert band.shape[1] == 2
    dist, _ = walls.query(band)
    # floor or ceiling points (38k each) would be ~14% of the band, mostly far from walls
    assert np.mean(dist < 0.05) > 0.99
    expected = np.count_nonzero((cloud[:, 2] >= 0.3) & (cloud[:, 2] <= 2.0))
    assert len(band) == pytest.approx(expected, rel=0.01)
    # the levelling it reports is the tilt it removed, and the floor it measured from
    assert levelling.tilt_deg == pytest.approx(TILT_DEG, abs=0.1)
    assert levelling.floor_z_m == pytest.approx(FLOOR_Z, abs=0.02)


def test_wall_band_is_deterministic(tilted: np.ndarray) -> None:
    np.testing.assert_array_equal(wall_band(tilted)[0], wall_band(tilted)[0])


def test_floor_below_a_stronger_ceiling_and_below_noise(cloud: np.ndarray) -> None:
    rng = np.random.default_rng(1)
    floor = np.abs(cloud[:, 2]) < 0.05
    thinned = cloud[~floor | (rng.random(len(cloud)) < 0.5)]  # ceiling now twice the floor
    sparse_below = np.column_stack([rng.uniform(0, 20, (300, 2)), rng.uniform(-3, -0.2, 300)])
    pts = np.vstack([thinned, sparse_below]) + [0.0, 0.0, -0.5]
    assert floor_height(pts) == pytest.approx(-0.5, abs=0.02)
    band, _ = wall_band(pts)
    assert len(band) == pytest.approx(np.count_nonzero((cloud[:, 2] >= 0.3)
                                                       & (cloud[:, 2] <= 2.0)), rel=0.01)


def test_walls_only_cloud_is_not_levelled_to_a_wall(cloud: np.ndarray) -> None:
    walls_only = cloud[(cloud[:, 2] > 0.1) & (cloud[:, 2] < WALL_HEIGHT - 0.1)]
    assert angle_deg(level_rotation(walls_only)) < 1.0


def test_empty_band_raises(cloud: np.ndarray) -> None:
    with pytest.raises(ValueError, match="no points between 3.0 and 4.0 m above the floor"):
        wall_band(cloud, 3.0, 4.0)
    with pytest.raises(ValueError, match="no points"):
        wall_band(np.full((5, 3), np.nan))
    with pytest.raises(ValueError, match=r"expected \(N, 3\) points"):
        wall_band(cloud[:, :2])


# --- clouds larger than one chunk ---------------------------------------------------------------


@pytest.fixture
def small_chunks(monkeypatch: pytest.MonkeyPatch) -> int:
    """wall_band works 50,000 points at a time (the building has about 440,000)."""
    monkeypatch.setattr(slice_module, "CHUNK", 50_000)
    return 50_000


def test_chunked_floor_and_band_equal_the_one_shot_ones(tilted: np.ndarray,
                                                        small_chunks: int) -> None:
    """With the same levelling, the two passes over chunks give the floor and the band that the
    whole levelled cloud gives."""
    rotation = level_rotation(tilted)
    levelled = tilted @ rotation.T
    floor = floor_height(levelled)
    z = levelled[:, 2] - floor
    band = levelled[(z >= 0.3) & (z <= 2.0), :2]
    got_floor, got_band = slice_module._band_by_chunks(tilted, rotation, 0.3, 2.0)
    assert got_floor == pytest.approx(floor, abs=1e-12)
    assert got_band.shape == band.shape
    np.testing.assert_allclose(got_band, band, atol=1e-12)


def test_chunked_band_of_a_float32_cloud_is_exact(tilted: np.ndarray, small_chunks: int) -> None:
    """A float32 cloud's candidates are held as float32 rows and levelled again: the band is
    bit for bit the one levelled once from the rows read as float64."""
    cloud = tilted.astype(np.float32)
    rotation = level_rotation(cloud)
    rows = cloud.astype(np.float64)
    def turned(axis: np.ndarray) -> np.ndarray:
        return rows[:, 0] * axis[0] + rows[:, 1] * axis[1] + rows[:, 2] * axis[2]

    floor, band = slice_module._band_by_chunks(cloud, rotation, 0.3, 2.0)
    z = turned(rotation[2]) - floor
    keep = (z >= 0.3) & (z <= 2.0)
    expected = np.column_stack([turned(rotation[0])[keep], turned(rotation[1])[keep]])
    assert np.array_equal(band, expected)


def test_chunked_wall_band_is_the_one_shot_band(tilted: np.ndarray, cloud: np.ndarray,
                                                small_chunks: int) -> None:
    """Levelled on every 9th point, in float32 with rows to skip, the band is the same walls:
    the known tilt and floor, the same number of points to 0.5 %."""
    whole, whole_levelling = wall_band(tilted)
    noisy = tilted.astype(np.float32)
    noisy[::1000, 1] = np.nan
    band, levelling = wall_band(noisy)
    assert levelling.tilt_deg == pytest.approx(TILT_DEG, abs=0.1)
    assert levelling.floor_z_m == pytest.approx(FLOOR_Z, abs=0.02)
    assert angle_deg(levelling.rotation @ whole_levelling.rotation.T) < 0.02
    assert levelling.floor_z_m == pytest.approx(whole_levelling.floor_z_m, abs=0.003)
    assert len(band) == pytest.approx(len(whole) * (1 - 1 / 1000), rel=0.005)
    np.testing.assert_array_equal(wall_band(noisy)[0], band)  # deterministic


def test_histogram_with_far_outliers() -> None:
    """Heights kilometres apart are binned by sorting, not counted in one huge array."""
    z = np.array([0.01, 0.02, 0.07, 5e4, -3e6])
    bins, counts = slice_module._histogram(slice_module._bins(z))
    np.testing.assert_array_equal(bins, [-60_000_000, 0, 1, 1_000_000])
    np.testing.assert_array_equal(counts, [1, 2, 1, 1])


def test_levelling_a_cloud_on_one_line_finds_no_plane_and_warns_nothing() -> None:
    """Found by the cloud property: RANSAC on collinear 3D points returns a zero plane model,
    whose normalising divided 0 by 0 (a NumPy RuntimeWarning on stderr before the error)."""
    import warnings

    from pcmapq.raster.levelling import level_rotation

    t = np.linspace(0.0, 30.0, 540)[:, None]
    points = np.array([0.2, 0.5, -0.5]) + t * np.array([-0.8, 0.35, -0.13])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.array_equal(level_rotation(points), np.eye(3))


def test_the_levelling_does_not_depend_on_the_order_of_the_points() -> None:
    """Two ground patches 1.5 degrees apart, as many points on each (a street whose slope
    changes): the dominant plane is either, and the seeded sample RANSAC searches picks it.
    The sample is drawn from the voxels in their index order, so the same cloud with its points
    in another order (written by another tool) is levelled the same."""
    rng = np.random.default_rng(3)
    xy = rng.uniform([0.0, -20.0], [20.0, 20.0], (120_000, 2))
    z = np.where(xy[:, 1] < 0.0, 0.0, xy[:, 1] * np.tan(np.radians(1.5)))
    ground = np.column_stack([xy, z + rng.normal(0.0, 0.01, len(xy))])
    r = level_rotation(ground)
    assert min(angle_deg(r), angle_deg(r @ rot_x(-1.5))) < 0.2  # levelled to one patch
    for seed in range(3):
        shuffled = ground[np.random.default_rng(seed).permutation(len(ground))]
        assert angle_deg(level_rotation(shuffled).T @ r) < 1e-6
