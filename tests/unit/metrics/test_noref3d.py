"""No-reference 3D metrics (MME, MPV, MOM) against map-metrics' figures, closed forms and a
per-point reference implementation; MOM's orthogonal planes found through a sample of the planar
points of a large cloud."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from numpy.lib import format as npy

from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.mapping.poses import read_poses
from pcmapq.metrics import noref, orthogonal, posed
from testkit.synth import room_corner


def _reference(points: np.ndarray, radius: float, min_knn: int) -> tuple[float, float, int]:
    """map-metrics' loop, verbatim in spirit: Open3D radius search, np.cov, det, eig."""
    import open3d as o3d

    tree = o3d.geometry.KDTreeFlann(o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points)))
    ent, var = [], []
    for p in points:
        _, idx, _ = tree.search_radius_vector_3d(p, radius)
        if len(idx) > min_knn:
            cov = np.cov(points[np.asarray(idx)].T)
            det = np.linalg.det(2 * np.pi * np.e * cov)
            if det > 0:
                ent.append(0.5 * np.log(det))
            var.append(min(np.linalg.eig(cov)[0]))
    return float(np.mean(ent)), float(np.mean(var)), len(var)


def test_matches_map_metrics_loop_on_a_random_cloud():
    rng = np.random.default_rng(3)
    points = rng.uniform(0, 1, (1500, 3)) * [2.0, 2.0, 0.3]
    mme, mpv, used = _reference(points, 0.25, 5)
    got = noref.scores(points, 0.25, 5)
    assert got.mpv_points == used
    assert got.mme == pytest.approx(mme, abs=1e-10)
    assert got.mpv == pytest.approx(mpv, rel=1e-9)


def test_neighbour_counts_equal_open3d_including_the_radius_boundary():
    import open3d as o3d

    # a half-metre grid: squared distances 0.25, 0.5, 1, 2.25 ... exactly; radii 0.5, 1, 1.5
    # hit them exactly (a point at exactly the radius is not a neighbour), 0.6 falls between
    g = np.indices((5, 4, 3)).reshape(3, -1).T * 0.5
    tree = o3d.geometry.KDTreeFlann(o3d.geometry.PointCloud(o3d.utility.Vector3dVector(g)))
    for radius in (0.5, 0.6, 1.0, 1.5):
        want = np.array([len(tree.search_radius_vector_3d(p, radius)[1]) for p in g])
        got = np.zeros(len(g))
        for idx, sums in noref.neighbourhood_sums(g, radius):
            got[idx] = sums[:, 0]
        np.testing.assert_array_equal(got, want)
    # strictly closer than the radius: the corner (0,0,0) at radius 1 has only itself
    counts, _ = noref.query_covariances(g, g[:1], 0.5)
    assert counts[0] == 1
    counts, _ = noref.query_covariances(g, g[:1], float(np.nextafter(0.5, 1.0)))
    assert counts[0] == 4


def test_plane_with_gaussian_noise_has_mpv_near_sigma_squared():
    rng = np.random.default_rng(0)
    sigma = 0.01
    n = 30_000
    points = np.column_stack([rng.uniform(0, 4, n), rng.uniform(0, 4, n),
                              rng.normal(0, sigma, n)])
    got = noref.scores(points, 0.2, 5)
    assert got.mpv == pytest.approx(sigma**2, rel=0.05)


def test_mme_of_a_gaussian_cloud_matches_the_closed_form():
    rng = np.random.default_rng(1)
    sigma = 0.3
    points = rng.normal(0, sigma, (4000, 3))
    # a radius wider than the cloud: every neighbourhood is the whole cloud
    got = noref.scores(points, 100.0, 5)
    exact = 0.5 * np.log(np.linalg.det(2 * np.pi * np.e * np.cov(points.T)))
    assert got.mme == pytest.approx(exact, abs=1e-9)
    assert got.mme == pytest.approx(1.5 * np.log(2 * np.pi * np.e * sigma**2), abs=0.05)
    assert got.mpv == pytest.approx(np.linalg.eigvalsh(np.cov(points.T))[0], rel=1e-9)


def test_chunks_give_the_same_figures_as_one_pass_and_runs_are_identical():
    rng = np.random.default_rng(2)
    points = rng.uniform(0, 1, (20_000, 3)) * [20.0, 3.0, 1.0]
    whole = noref.scores(points, 0.3, 5, chunk_points=10**9)
    sliced = noref.scores(points, 0.3, 5, chunk_points=3_000)
    assert sliced.mpv_points == whole.mpv_points and sliced.mme_points == whole.mme_points
    assert sliced.mme == pytest.approx(whole.mme, abs=1e-12)
    assert sliced.mpv == pytest.approx(whole.mpv, rel=1e-12)
    assert noref.scores(points, 0.3, 5, chunk_points=3_000, workers=1) == sliced
    assert noref.scores(points, 0.3, 5, chunk_points=3_000, workers=3) == sliced


def test_sums_equal_a_kd_tree_count_and_np_cov_per_point():
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(8)
    # a dense clump (one cell of many points: products cut into row chunks) and a sparse spread
    points = np.vstack([rng.normal(0, 0.05, (3000, 3)), rng.uniform(-5, 5, (2000, 3))])
    radius = 0.4
    counts = cKDTree(points).query_ball_point(points, noref.strict_radius(radius),
                                              return_length=True)
    got_n, got_cov = np.zeros(len(points)), np.zeros((len(points), 3, 3))
    for idx, sums in noref.neighbourhood_sums(points, radius):
        got_n[idx], got_cov[idx] = sums[:, 0], noref.covariances(sums)
    np.testing.assert_array_equal(got_n, counts)
    tree = cKDTree(points)
    for i in rng.choice(np.flatnonzero(counts > 3), 50, replace=False):
        near = points[tree.query_ball_point(points[i], noref.strict_radius(radius))]
        np.testing.assert_allclose(got_cov[i], np.cov(near.T), rtol=1e-9, atol=1e-15)


def test_sparse_points_have_no_figure():
    """No point with more than min_knn neighbours: map-metrics gives 0.0 (a figure better than
    any real map's); here MME and MPV are not a number, null in the JSON with the reason, n/a
    on the terminal."""
    from pcmapq.evaluation.inspect_map import summary_lines
    from pcmapq.metrics.inspection import noref_figures

    points = np.arange(30, dtype=float).reshape(10, 3) * 10.0
    got = noref.scores(points, 0.5, 5)
    assert math.isnan(got.mme) and math.isnan(got.mpv)
    assert (got.mme_points, got.mpv_points, got.total_points) == (0, 0, 10)
    record = noref_figures(points, radius=0.5)
    assert record["mme"] is None and record["mpv"] is None
    assert record["mme_note"] == record["mpv_note"] == (
        "no point has more than 5 neighbours within 0.5 m (a larger radius, or a denser cloud)")
    lines = summary_lines({"map": {"path": "m.ply", "kind": "cloud"}, "cloud": record,
                           "grid": None})
    assert "MME       n/a (no point has more than 5 neighbours within 0.5 m" in lines[2]
    assert lines[3].startswith("MPV       n/a (no point has more than 5")
    from pcmapq.report.table import _noref_parts  # eval's table of both sides' figures

    assert _noref_parts({"cloud": record, "grid": None})[:2] == ["MME n/a", "MPV n/a"]


def test_flat_neighbourhoods_have_no_entropy():
    """Points on a plane: MPV is 0 m^2 over every point, MME has no point (det = 0)."""
    from pcmapq.metrics.inspection import noref_figures

    grid = np.stack(np.meshgrid(np.arange(10.0), np.arange(10.0)), axis=-1).reshape(-1, 2)
    record = noref_figures(np.column_stack([grid * 0.1, np.zeros(100)]), radius=0.5)
    assert record["mpv"] == 0.0 and record["mpv_note"] is None
    assert record["mme"] is None and "has volume" in record["mme_note"]


def test_mom_sums_the_median_plane_variance_of_each_plane():
    rng = np.random.default_rng(4)
    sigmas = (0.005, 0.01, 0.02)
    walls = []
    for axis, s in enumerate(sigmas):
        w = rng.uniform(0, 3, (30_000, 3))
        w[:, axis] = rng.normal(0, s, len(w))
        walls.append(w)
    points = np.vstack(walls)
    planes = [w[rng.choice(len(w), 50, replace=False)] * [1, 1, 1] for w in walls]
    planes = [p[np.all(np.delete(p, a, axis=1) > 0.5, axis=1) & np.all(np.delete(p, a, axis=1)
                                                                       < 2.5, axis=1)]
              for a, p in enumerate(planes)]
    got = noref.mom(points, planes, 0.2)
    assert got == pytest.approx(sum(s * s for s in sigmas), rel=0.1)


def test_orthogonal_subset_of_a_room_corner():
    planes = orthogonal.extract_orthogonal_subset(room_corner(5), 0.2)
    assert len(planes) == 3
    normals = np.stack([np.linalg.eigh(np.cov(p.T))[1][:, 0] for p in planes])
    assert np.abs(normals @ normals.T - np.eye(3)).max() < 0.05
    assert sorted(int(np.argmax(np.abs(n))) for n in normals) == [0, 1, 2]


def test_orthogonal_subset_of_one_plane_is_refused():
    rng = np.random.default_rng(6)
    plane = np.column_stack([rng.uniform(0, 2, (3000, 2)), rng.normal(0, 0.002, 3000)])
    with pytest.raises(EvaluationError):
        orthogonal.extract_orthogonal_subset(plane, 0.2)


def test_place_puts_each_scan_at_its_pose_relative_to_the_first():
    first = np.eye(4)
    first[:3, 3] = [10.0, 0.0, 0.0]
    second = np.eye(4)
    second[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # 90 degrees about z
    second[:3, 3] = [10.0, 5.0, 0.0]
    cloud = np.array([[1.0, 0.0, 0.0]])
    got = posed.place([cloud, cloud], [first, second])
    np.testing.assert_allclose(got, [[1.0, 0.0, 0.0], [0.0, 6.0, 0.0]], atol=1e-12)


def test_pose_files_kitti_tum_and_folder(tmp_path):
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rot, [1.0, 2.0, 3.0]
    kitti = tmp_path / "kitti.txt"
    np.savetxt(kitti, np.stack([np.eye(4)[:3].ravel(), pose[:3].ravel()]))
    tum = tmp_path / "tum.txt"
    s = math.sqrt(0.5)  # 90 degrees about z: qz = qw = sqrt(1/2)
    tum.write_text(f"# t x y z qx qy qz qw\n0 0 0 0 0 0 0 1\n1 1 2 3 0 0 {s!r} {s!r}\n")
    folder = tmp_path / "poses"
    folder.mkdir()
    np.savetxt(folder / "b.txt", pose)
    np.savetxt(folder / "a.txt", np.eye(4))
    for source in (kitti, tum, folder):
        got = read_poses(source)
        assert len(got) == 2
        np.testing.assert_allclose(got[0], np.eye(4), atol=1e-12)
        np.testing.assert_allclose(got[1], pose, atol=1e-12)
    bad = tmp_path / "bad.txt"
    bad.write_text("1 2 3\n")
    with pytest.raises(InputError, match="bad.txt"):
        read_poses(bad)


class _Evil:
    def __reduce__(self):
        return (print, ("pickled code ran",))


def test_orthogonal_subset_file_runs_no_pickled_code(tmp_path, capsys):
    good = np.empty(2, dtype=object)
    good[0], good[1] = np.zeros((4, 3)), np.ones((5, 3))
    path = tmp_path / "orth.npy"
    np.save(path, good, allow_pickle=True)
    planes = posed.read_orthogonal_subset(path)
    assert [p.shape for p in planes] == [(4, 3), (5, 3)]
    evil = tmp_path / "evil.npy"
    with evil.open("wb") as f:
        npy.write_array_header_1_0(f, {"descr": "|O", "fortran_order": False, "shape": (1,)})
        pickle.dump(_Evil(), f)
    with pytest.raises(InputError, match="evil.npy"):
        posed.read_orthogonal_subset(evil)
    assert "pickled code ran" not in capsys.readouterr().out


def test_noref_figures_extracts_a_subset_or_says_why_not():
    from pcmapq.metrics.inspection import noref_figures

    corner = room_corner(7)
    got = noref_figures(corner, radius=0.2)
    assert got["orth_subset"] == "extracted" and len(got["orth_plane_points"]) == 3
    assert got["mom"] == pytest.approx(noref.mom(corner, orthogonal.extract_orthogonal_subset(
        corner, 0.2), 0.2))
    assert got["points"] == 4500 and got["mpv"] == pytest.approx(noref.scores(corner, 0.2).mpv)
    flat = corner[3000:]  # the third wall alone
    got = noref_figures(flat, radius=0.2)
    assert got["mom"] is None and "orthogonal" in got["mom_note"]


def test_scores_find_the_planar_points_of_the_subset_extraction_in_the_same_pass():
    corner = room_corner(11)
    got = noref.scores(corner, 0.2, with_flat=True)
    np.testing.assert_array_equal(got.flat, orthogonal.planar_points(corner, 0.2))
    assert got.flat.any() and noref.scores(corner, 0.2).flat is None
    assert (got.mme, got.mpv) == (noref.scores(corner, 0.2).mme, noref.scores(corner, 0.2).mpv)


def test_planes_found_through_a_sample_of_the_planar_points():
    """A room corner (4,500 points on three walls): clustering 500 of its planar normals finds
    the same three walls, every planar point of each on it, as clustering all of them."""
    corner = room_corner(5)
    whole = orthogonal.extract_orthogonal_subset(corner, 0.2)
    sampled = orthogonal.extract_orthogonal_subset(corner, 0.2, max_ward=500)
    axes = [int(np.argmax(np.abs(np.linalg.eigh(np.cov(p.T))[1][:, 0]))) for p in sampled]
    assert sorted(axes) == [0, 1, 2]
    for plane, axis in zip(sampled, axes, strict=True):
        assert np.abs(plane[:, axis]).max() < 0.01  # every point on its wall
    assert sum(map(len, sampled)) >= 0.98 * sum(map(len, whole))
    assert sum(map(len, whole)) > 500


def _brute_best_triple(means: np.ndarray, sizes: np.ndarray, eps: float):
    """Every i < j < k in lexicographic order, the first of the largest total kept."""
    adj = np.abs(means @ means.T) < eps
    best, total = None, -1
    n = len(means)
    for i in range(n):
        for j in range(i + 1, n):
            for k in range(j + 1, n):
                if adj[i, j] and adj[i, k] and adj[j, k] and sizes[i] + sizes[j] + sizes[k] > total:
                    best, total = (i, j, k), sizes[i] + sizes[j] + sizes[k]
    return best


@pytest.mark.parametrize("seed", range(6))
def test_best_triple_is_the_largest_orthogonal_triple_first_among_equals(seed):
    """Normals near the three axes (several clusters each) and random ones, sizes with ties:
    the triple found is the brute-force search's."""
    rng = np.random.default_rng(seed)
    axes = np.eye(3)[rng.integers(0, 3, 24)] + rng.normal(0, 0.03, (24, 3))
    means = np.vstack([axes, rng.normal(size=(10, 3))])
    means /= np.linalg.norm(means, axis=1, keepdims=True)
    sizes = rng.integers(6, 12, len(means))  # few values: many equal totals
    want = _brute_best_triple(means, sizes, orthogonal.ORTHOGONAL_COS)
    assert want is not None
    assert orthogonal._best_triple(means, sizes, orthogonal.ORTHOGONAL_COS) == want


def test_ward_tree_cut_as_scipys():
    """The clusters of 3,000 noisy normals (fastcluster's tree from the vectors) are SciPy's
    Ward clusters, label for label."""
    from scipy.cluster.hierarchy import fcluster, ward

    rng = np.random.default_rng(2)
    normals = np.eye(3)[rng.integers(0, 3, 3000)] + rng.normal(0, 0.05, (3000, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    tree = ward(normals)
    want = fcluster(tree, int(np.count_nonzero(tree[:, 2] >= orthogonal.WARD_CUT)) + 1,
                    criterion="maxclust")
    labels, _, _ = orthogonal._clusters(normals, 0, len(normals))
    np.testing.assert_array_equal(labels, want)
