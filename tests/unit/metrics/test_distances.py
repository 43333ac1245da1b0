"""Distance metrics with known answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from pcmapq.core.grid import MetricGrid
from pcmapq.core.morphology import distance_to
from pcmapq.metrics.distances import distances, nearest_distance

GRID = MetricGrid(0.05, (0.0, 0.0, 0.0), (200, 200))


def wall(col: int, rows=slice(20, 180)) -> np.ndarray:
    occ = np.zeros(GRID.shape, bool)
    occ[rows, col] = True
    return occ


def test_wall_shifted_by_a_known_distance():
    truth, map_ = wall(50), wall(55)  # 5 cells = 0.25 m apart
    d = distances(truth, map_, np.ones(GRID.shape, bool), GRID, taus=(0.2, 0.3))
    for stats in (d.accuracy, d.completeness):
        assert stats.mean == pytest.approx(0.25) and stats.median == pytest.approx(0.25)
        assert stats.rmse == pytest.approx(0.25) and stats.p95 == pytest.approx(0.25)
    assert d.chamfer_m == pytest.approx(0.25)
    (at_02, at_03) = d.fscores
    assert (at_02.precision, at_02.recall, at_02.f) == (0.0, 0.0, 0.0)
    assert (at_03.precision, at_03.recall, at_03.f) == (1.0, 1.0, 1.0)


def test_completeness_counts_only_the_footprint():
    truth = wall(50) | wall(150)
    map_ = wall(50)
    footprint = np.zeros(GRID.shape, bool)
    footprint[:, :100] = True
    inside = distances(truth, map_, footprint, GRID)
    assert inside.completeness.mean == 0.0 and inside.fscores[0].recall == 1.0
    whole = distances(truth, map_, np.ones(GRID.shape, bool), GRID)
    assert whole.completeness.mean == pytest.approx(0.5 * 5.0)  # half the truth is 5 m away
    assert whole.fscores[-1].recall == pytest.approx(0.5)


def test_missing_map_gives_no_accuracy():
    d = distances(wall(50), np.zeros(GRID.shape, bool), np.ones(GRID.shape, bool), GRID)
    assert d.accuracy.count == 0 and d.accuracy.mean is None and d.chamfer_m is None
    assert d.completeness.mean is None and d.completeness.count == 160
    assert all(f.f == 0.0 for f in d.fscores)


def test_distance_transform_is_exact_euclidean():
    """The one distance transform: a 3-4-5 triangle, whole cells that compare exactly with a
    threshold in metres, SciPy's exact transform within float32 rounding, inf to nothing."""
    target = np.zeros((60, 70), bool)
    target[10, 20] = target[45, 3] = True
    cells = distance_to(target)
    assert cells.dtype == np.float32 and cells[13, 24] == 5.0 and cells[10, 20] == 0.0
    grid = MetricGrid(0.05, (0.0, 0.0, 0.0), target.shape)
    metres = nearest_distance(target, grid)
    assert metres[14, 20].dtype == np.float64 and metres[14, 20] == 4 * 0.05  # 4 cells x 0.05
    # read in metres, any index: the values of a float64 field of metres, in half its memory
    whole = np.multiply(cells, 0.05, dtype=np.float64)
    assert np.array_equal(metres[...], whole) and metres.cells.dtype == np.float32
    assert np.array_equal(metres[target | (cells > 30)], whole[target | (cells > 30)])
    rng = np.random.default_rng(0)
    sparse = rng.random((300, 400)) < 0.001
    exact = ndimage.distance_transform_edt(~sparse)
    np.testing.assert_allclose(distance_to(sparse), exact, rtol=1.2e-7, atol=0)
    assert np.isinf(distance_to(np.zeros((5, 5), bool))).all()
    assert np.isinf(nearest_distance(np.zeros(GRID.shape, bool), GRID)[...]).all()


def test_distances_3d_are_the_kd_tree_distances_and_a_known_offset():
    """Two walls 0.2 m apart: every distance is 0.2 m; on random clouds, exactly SciPy's."""
    from scipy.spatial import cKDTree

    from pcmapq.core.voxels import voxel_centroids
    from pcmapq.metrics.distances import distances_3d

    y, z = np.meshgrid(np.arange(0.025, 4, 0.05), np.arange(0.025, 2, 0.05))
    wall_a = np.column_stack([np.full(y.size, 1.025), y.ravel(), z.ravel()])
    d = distances_3d(wall_a, wall_a + [0.2, 0.0, 0.0], taus=(0.1, 0.25))
    for stats in (d.accuracy, d.completeness):
        assert stats.count == y.size and stats.mean == pytest.approx(0.2)
        assert stats.max == pytest.approx(0.2)
    assert [f.f for f in d.fscores] == [0.0, 1.0]
    rng = np.random.default_rng(0)
    a, b = rng.uniform(0, 5, (20_000, 3)), rng.uniform(0, 5, (15_000, 3))
    d = distances_3d(a, b, 0.1)
    va, vb = voxel_centroids(a, 0.1), voxel_centroids(b, 0.1)
    assert d.accuracy.mean == cKDTree(vb).query(va)[0].mean()
    assert d.completeness.max == cKDTree(va).query(vb)[0].max()
    empty = distances_3d(np.zeros((0, 3)), b, 0.1)
    assert empty.accuracy.count == 0 and empty.completeness.count == len(vb)
    assert empty.fscores[0].recall == 0.0
