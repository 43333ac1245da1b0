"""MapEval's AWD and SCS with known answers, and against a plain reference computation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import sqrtm
from scipy.spatial.transform import Rotation

from pcmapq.core.errors import InputError
from pcmapq.metrics.map_gaussians import gaussian_w2, map_gaussians, voxel_gaussians
from testkit.mapeval import reference_awd_scs


def in_voxels(cells: tuple[int, int, int] = (5, 4, 2), per: int = 150, voxel: float = 3.0,
              seed: int = 0) -> np.ndarray:
    """``per`` points in each of a block of voxels, all 0.6 m or more inside its faces (N, 3),
    metres, an elongated blob in each (unlike covariances)."""
    rng = np.random.default_rng(seed)
    corners = np.stack(np.meshgrid(*(np.arange(c) for c in cells), indexing="ij"),
                       axis=-1).reshape(-1, 3) * voxel
    blobs = rng.normal(0.0, [0.3, 0.15, 0.05], (len(corners), per, 3))
    turns = Rotation.random(len(corners), random_state=seed).as_matrix()
    blobs = np.clip(np.einsum("vij,vpj->vpi", turns, blobs), -0.85, 0.85)
    return (corners[:, None, :] + voxel / 2 + blobs).reshape(-1, 3)


def room(n: int = 8000, seed: int = 1) -> np.ndarray:
    """A 12 x 12 x 6 m room's floor and two walls, 1 cm noise (N, 3), metres."""
    rng = np.random.default_rng(seed)
    pts = rng.uniform([0, 0, 0], [12, 12, 6], (n, 3))
    face = rng.integers(0, 3, n)
    pts[np.arange(n), face] = rng.normal(0.0, 0.01, n) + np.where(face == 2, 0.2, 0.4)
    return pts


def test_identical_clouds_give_zero():
    cloud = in_voxels()
    r = map_gaussians(cloud, cloud.copy())
    assert (r.awd_m, r.scs, r.voxels) == (0.0, 0.0, 40)


@pytest.mark.parametrize("d", [0.05, 0.3, 0.55])
def test_a_cloud_shifted_along_x_gives_the_shift(d):
    """Every voxel keeps its points: equal covariances, means d apart, so W2 = d in each and
    the distances do not vary (SCS 0)."""
    cloud = in_voxels()
    r = map_gaussians(cloud + [d, 0.0, 0.0], cloud)
    assert r.awd_m == pytest.approx(d, abs=1e-9)
    assert r.scs == pytest.approx(0.0, abs=1e-6)
    assert r.voxels == 40


def test_w2_matches_the_closed_form_with_scipy_square_roots():
    rng = np.random.default_rng(3)
    a, b = (rng.normal(size=(50, 3, 3)) for _ in range(2))
    eye = 0.01 * np.eye(3)  # every eigenvalue above the floor of 1e-6 m^2
    cov_a, cov_b = a @ a.transpose(0, 2, 1) + eye, b @ b.transpose(0, 2, 1) + eye
    mean_a, mean_b = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    got = gaussian_w2(mean_a, cov_a, mean_b, cov_b)
    for i in range(50):
        root = np.real(sqrtm(cov_a[i]))
        cross = np.trace(np.real(sqrtm(root @ cov_b[i] @ root)))
        want = np.sqrt(np.sum((mean_a[i] - mean_b[i]) ** 2) + np.trace(cov_a[i] + cov_b[i])
                       - 2 * cross)
        assert got[i] == pytest.approx(want, rel=1e-9)


def test_w2_of_diagonal_covariances():
    """Commuting covariances: W2^2 = |mean shift|^2 + sum (sqrt a_i - sqrt b_i)^2."""
    a, b = np.diag([1.0, 4.0, 0.25]), np.diag([4.0, 1.0, 0.25])
    got = gaussian_w2(np.zeros((1, 3)), a[None], np.array([[3.0, 0.0, 0.0]]), b[None])
    assert got[0] == pytest.approx(np.sqrt(9.0 + 1.0 + 1.0))


def test_voxel_gaussians_are_sample_means_and_covariances_far_from_the_origin():
    cloud = in_voxels(cells=(2, 1, 1), per=120) + [399_999.0, 3.0e6, 30.0]  # whole voxels
    keys, mean, cov = voxel_gaussians(cloud, 3.0, 100)
    assert len(keys) == 2 and np.all(np.diff(keys) > 0)
    for i, half in enumerate((cloud[:120], cloud[120:])):
        np.testing.assert_allclose(mean[i], half.mean(axis=0), rtol=0, atol=1e-9)
        np.testing.assert_allclose(cov[i], np.cov(half.T, ddof=1), rtol=0, atol=1e-9)


def test_voxels_with_too_few_points_in_either_cloud_are_left_out():
    cloud = in_voxels(cells=(2, 1, 1), per=120)
    sparse = np.vstack([cloud[:120], cloud[120:180]])  # the second voxel holds 60 points
    r = map_gaussians(sparse, cloud)
    assert r.voxels == 1
    assert r.scs is None  # no voxel has a counted neighbour
    assert map_gaussians(cloud, cloud, min_points=121) == map_gaussians(
        cloud[:0], cloud, min_points=121)


def test_nothing_in_common_gives_none():
    r = map_gaussians(in_voxels(), in_voxels() + [100.0, 0.0, 0.0])
    assert (r.awd_m, r.scs, r.voxels) == (None, None, 0)


@pytest.mark.parametrize(("voxel", "min_points", "radius"), [(3.0, 100, 5), (1.0, 10, 2),
                                                             (1.5, 20, 1)])
def test_equals_the_plain_reference(voxel, min_points, radius):
    """A room and a bent, noisier copy of it (a few thousand points): AWD, SCS and the
    voxels compared are the reference's, written one voxel at a time."""
    truth = room()
    rng = np.random.default_rng(2)
    bent = room(7000, seed=4) + rng.normal(0.0, 0.02, (7000, 3))
    bent[:, 2] += 0.01 * bent[:, 0]  # a slope: distances grow along x
    r = map_gaussians(bent, truth, voxel, min_points, radius)
    awd, scs, voxels = reference_awd_scs(bent, truth, voxel, min_points, radius)
    assert r.voxels == voxels > 10
    assert r.awd_m == pytest.approx(awd, rel=1e-9)
    assert r.scs == pytest.approx(scs, rel=1e-9)


def test_clouds_far_from_the_origin_give_the_figures_near_it():
    cloud = in_voxels()
    near = map_gaussians(cloud + [0.2, 0.1, 0.0], cloud)
    utm = [6.0e5, 5.1e6, 300.0]  # whole voxels: the same voxels
    far = map_gaussians(cloud + [0.2, 0.1, 0.0] + utm, cloud + utm)
    assert far.voxels == near.voxels
    assert far.awd_m == pytest.approx(near.awd_m, abs=1e-7)


def test_clouds_wider_than_the_voxel_index_are_refused():
    cloud = in_voxels(cells=(1, 1, 1))
    with pytest.raises(InputError, match="larger voxel"):
        map_gaussians(cloud, np.vstack([cloud, cloud + [0.0, 0.0, 7.0e6]]))


def test_a_cloud_is_read_chunk_by_chunk_with_the_same_figures(monkeypatch):
    """A large float32 cloud (a file mapped into memory) is read CHUNK points at a time: the
    figures are those of one pass over all its points, bit for bit, and the memory taken
    stays below a float64 copy of the cloud (none is made)."""
    import tracemalloc

    import pcmapq.metrics.map_gaussians as module

    truth = room(200_000).astype(np.float32)
    bent = (room(200_000, seed=4) + [0.03, 0.0, 0.0]).astype(np.float32)
    whole = map_gaussians(bent, truth, 3.0, 100, 2)  # one chunk
    monkeypatch.setattr(module, "CHUNK", 4096, raising=False)
    tracemalloc.start()
    try:
        chunked = map_gaussians(bent, truth, 3.0, 100, 2)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert chunked == whole and whole.voxels > 10
    assert peak < 2 * truth.nbytes


def test_the_box_of_voxels_and_the_voxels_listed_give_the_same_gaussians(monkeypatch):
    """A cloud summed on every voxel of its box, or on its voxels listed in a pass first:
    the same voxels, means and covariances, bit for bit."""
    import pcmapq.metrics.map_gaussians as module

    cloud = room(20_000) + [6.0e5, 5.1e6, 300.0]
    corner = np.floor(cloud.min(axis=0) / 1.5) * 1.5
    boxed = voxel_gaussians(cloud, 1.5, 10, corner)
    monkeypatch.setattr(module, "DENSE_CELLS", 0, raising=False)
    listed = voxel_gaussians(cloud, 1.5, 10, corner)
    assert len(boxed[0]) > 50
    for a, b in zip(boxed, listed, strict=True):
        assert a.shape == b.shape and np.array_equal(a, b)
