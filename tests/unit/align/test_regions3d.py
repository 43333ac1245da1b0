"""Where a 3D map bends: a street whose far end sank, or that tilts more and more along its
length, registered region by region against the straight street (known answers)."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.align import regions3d
from pcmapq.align.regions3d import Consistency3D, regions_3d
from pcmapq.mapping.scan_map import ScanGrid
from testkit.street import street, street_run, sunk, tilted

#: The tests' working voxel and tile, metres (a tile edge lies on x = 10).
VOXEL, TILE = 0.2, 10.0


@pytest.fixture(scope="module")
def truth() -> np.ndarray:
    return street(0.0, 30.0, spacing=0.15, seed=0)


@pytest.fixture(scope="module")
def scan() -> np.ndarray:
    """The same street sampled again: fresh noise, the same layout."""
    cloud = street(0.0, 30.0, spacing=0.15, seed=0)
    return cloud + np.random.default_rng(7).normal(0.0, 0.005, cloud.shape)


@pytest.fixture(scope="module")
def sank(truth, scan) -> Consistency3D:
    """The regions of the scan lowered by 0.3 m beyond x = 10."""
    return regions_3d(sunk(scan, 10.0, 0.3), truth, tile_m=TILE, voxel=VOXEL)


def test_a_street_that_sank_beyond_10_m(sank):
    """Lowered by 0.3 m beyond x = 10: the regions there lie 0.3 m low (dz -0.3 within 5 cm),
    the others in place (|dz| < 5 cm), every region held, and the largest |dz| beyond 10 m."""
    c = sank
    assert len(c.points) == 6 and c.held.all()
    far = c.centre[:, 0] > 10.0
    assert far.any() and (~far).any()
    np.testing.assert_allclose(c.offset[far, 2], -0.3, atol=0.05)
    assert np.all(np.abs(c.offset[~far, 2]) < 0.05)
    assert np.all(np.abs(c.offset[:, :2]) < 0.05)  # nothing moved across the street
    assert np.all(c.fit_after[far] > c.fit_before[far])
    k = c.largest_dz()
    assert k is not None and c.centre[k, 0] > 10.0
    assert c.largest() is not None and c.centre[c.largest(), 0] > 10.0


def test_a_tilt_growing_along_the_street(truth, scan):
    """A pitch growing by 0.05 deg a metre: each region lies lower the farther along it is,
    dz within 2 cm of the drop at its centroid, and pitched up by about the slope there."""
    c = regions_3d(tilted(scan, 0.05), truth, tile_m=TILE, voxel=VOXEL)
    rate = np.tan(np.radians(0.05))
    order = np.argsort(c.centre[:, 0])
    for side in (c.centre[order, 1] < 0, c.centre[order, 1] > 0):
        dz = c.offset[order][side, 2]
        assert np.all(np.diff(dz) < 0)  # lower and lower along x
    np.testing.assert_allclose(c.offset[:, 2], -rate * c.centre[:, 0] ** 2 / 2, atol=0.02)
    # the map's region turns nose down along +x: a positive pitch about y
    np.testing.assert_allclose(c.angles_deg[:, 1], 0.05 * c.centre[:, 0], atol=0.1)
    assert c.centre[c.largest_dz(), 0] > 20.0


def test_a_ground_alone_is_not_held():
    """A flat ground pins z, roll and pitch only: its region is registered, not held."""
    rng = np.random.default_rng(0)
    ground = np.column_stack([rng.uniform(0, 5, (20000, 2)), rng.normal(0, 0.005, 20000)])
    c = regions_3d(ground - [0, 0, 0.2], ground, tile_m=TILE, voxel=VOXEL)
    assert len(c.points) == 1 and not c.held[0]
    assert c.offset[0, 2] == pytest.approx(-0.2, abs=0.01)
    assert c.largest() is None and c.largest_dz() is None


def test_the_truth_frame_is_levelled_first(truth, scan):
    """With the truth's levelling given, both clouds are turned by it: a street tilted 2 deg
    about x, and its map sunk beyond 10 m along the tilted street, reads as the level one."""
    turn = np.radians(2.0)
    tilt = np.array([[1, 0, 0], [0, np.cos(turn), -np.sin(turn)], [0, np.sin(turn),
                                                                    np.cos(turn)]])
    c = regions_3d(sunk(scan, 10.0, 0.3) @ tilt.T, truth @ tilt.T, tile_m=TILE, voxel=VOXEL,
                   level=tilt.T)
    far = c.centre[:, 0] > 10.0
    np.testing.assert_allclose(c.offset[far, 2], -0.3, atol=0.05)
    assert np.all(np.abs(c.offset[~far, 2]) < 0.05)


def test_empty_inputs_give_no_region():
    c = regions_3d(np.zeros((0, 3)), np.zeros((0, 3)), tile_m=TILE, voxel=VOXEL)
    assert isinstance(c, Consistency3D) and len(c.points) == 0 and c.largest() is None


def test_repeatable(truth, scan, sank):
    """The same inputs give the same regions, bit for bit."""
    a, b = sank, regions_3d(sunk(scan, 10.0, 0.3), truth, tile_m=TILE, voxel=VOXEL)
    for name in ("centre", "offset", "angles_deg", "fit_before", "fit_after", "held"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def _small_gicps_fit(own, window, voxel):
    """A region's ICP as small_gicp's own ``align`` gives it: move and Hessian per pair."""
    import small_gicp

    tgt, src = small_gicp.PointCloud(window), small_gicp.PointCloud(own)
    tree = small_gicp.KdTree(tgt, num_threads=1)
    small_gicp.estimate_normals(tgt, tree, num_neighbors=regions3d.NORMAL_NEIGHBOURS,
                                num_threads=1)
    move, hessian = np.eye(4), np.zeros((6, 6))
    for units in regions3d.STAGES:
        result = small_gicp.align(tgt, src, tree, init_T_target_source=move,
                                  registration_type="PLANE_ICP",
                                  max_correspondence_distance=units * voxel, num_threads=1,
                                  max_iterations=regions3d.ITERATIONS,
                                  rotation_epsilon=regions3d.SETTLED,
                                  translation_epsilon=regions3d.SETTLED)
        move = np.array(result.T_target_source, dtype=np.float64)
        hessian = np.array(result.H, dtype=np.float64) / max(int(result.num_inliers), 1)
    return move, hessian


def _as_small_gicp(monkeypatch) -> list:
    """Each region's ICP, once computed by pcmapq, computed again by small_gicp's own ``align``
    (the regions then small_gicp's); the pairs of Hessians per pair, pcmapq's and its."""
    hessians = []
    real = regions3d._register

    def both(nearest, normals, voxel):
        ours = real(nearest, normals, voxel)
        theirs = _small_gicps_fit(nearest.source, nearest.target, voxel)
        hessians.append((ours[1], theirs[1]))
        return theirs

    monkeypatch.setattr(regions3d, "_register", both)
    return hessians


def test_the_regions_are_small_gicps(monkeypatch, truth, scan, sank):
    """Each region's ICP, computed by pcmapq, gives the regions that small_gicp's own
    ``align`` gives (to the micrometre and 1e-6 degree the regions are kept at), and the
    same Hessian per pair to 1e-9."""
    hessians = _as_small_gicp(monkeypatch)
    b = regions_3d(sunk(scan, 10.0, 0.3), truth, tile_m=TILE, voxel=VOXEL)
    assert len(hessians) == len(b.points) > 0
    for ours, theirs in hessians:
        np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-12)
    for name in ("centre", "offset", "angles_deg", "fit_before", "fit_after", "held"):
        np.testing.assert_array_equal(getattr(sank, name), getattr(b, name))


def test_the_stretches_are_small_gicps_against_the_whole_truth(monkeypatch, truth, scan):
    """Stretches share one KD-tree and the normals of all the truth's points: each stretch's
    ICP is small_gicp's ``align`` against all of them, to the same figures and Hessians (to
    1e-9 of their largest entry: the normals come from the truth's own coordinates, not
    small_gicp's centred copy)."""
    seen, poses = street_run(scan, 12, step=2.0)
    grid = ScanGrid(0.1)
    for index, (points, pose) in enumerate(zip(seen, poses, strict=True)):
        grid.add(points + pose[:3, 3], index)
    built = grid.map()
    ours = regions_3d(built.points, truth, voxel=VOXEL, scan=built.scan)
    hessians = _as_small_gicp(monkeypatch)
    theirs = regions_3d(built.points, truth, voxel=VOXEL, scan=built.scan)
    assert len(hessians) == len(theirs.points) == 3
    for mine, its in hessians:
        np.testing.assert_allclose(mine, its, rtol=1e-9, atol=1e-9 * np.abs(its).max())
    for name in ("centre", "offset", "angles_deg", "fit_before", "fit_after", "held"):
        np.testing.assert_array_equal(getattr(ours, name), getattr(theirs, name))


def test_a_long_map_gets_larger_tiles():
    """A 400 m long ground is cut into at most 32 tiles along it: 12.5 m each."""
    rng = np.random.default_rng(1)
    ground = np.column_stack([rng.uniform(0, 400, (40000,)), rng.uniform(0, 4, 40000),
                              np.zeros(40000)])
    assert regions_3d(ground, ground, tile_m=TILE, voxel=0.5).tile_m == pytest.approx(12.5,
                                                                                     rel=1e-3)


def test_a_large_cloud_is_streamed_not_copied(monkeypatch, scan):
    """A float32 truth of more points than are streamed (a file mapped into memory): its
    voxel centroids are read in chunks, the regions those of its float64 copy, and the memory
    taken stays below that copy's size (none is made)."""
    import tracemalloc

    from pcmapq.core import voxel_table

    dense = street(0.0, 30.0, spacing=0.05, seed=0).astype(np.float32)
    expected = regions_3d(scan, dense.astype(np.float64), tile_m=TILE, voxel=VOXEL)
    monkeypatch.setattr(voxel_table, "CHUNK", 4096)
    tracemalloc.start()
    try:
        got = regions_3d(scan, dense, tile_m=TILE, voxel=VOXEL)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    for name in ("centre", "offset", "angles_deg", "fit_before", "fit_after", "held"):
        np.testing.assert_array_equal(getattr(got, name), getattr(expected, name))
    assert peak < 2 * dense.nbytes


def test_a_run_whose_last_scans_sank_is_cut_into_stretches():
    """A car's 30-scan run along the street (a scan a metre, 8 m of reach), mapped with its
    scans from the 20th on placed 0.3 m too low, each map point carrying its scan: the regions
    are stretches of 4 scans; those of scans 20 on lie 0.3 m low (within 5 cm), those before
    16 in place, every one held, and the largest |dz| is a sunk stretch's."""
    truth = street(-10.0, 40.0, spacing=0.15, seed=0)
    drawn = truth + np.random.default_rng(7).normal(0.0, 0.005, truth.shape)
    seen, poses = street_run(drawn, 30)
    poses[20:, 2, 3] -= 0.3
    grid = ScanGrid(0.1)
    for index, (points, pose) in enumerate(zip(seen, poses, strict=True)):
        grid.add(points + pose[:3, 3], index)
    built = grid.map()
    c = regions_3d(built.points, truth, voxel=VOXEL, scan=built.scan)
    assert c.tile_m is None and c.stretch == 4 and c.cut() == "stretches of 4 scans"
    assert c.scans.tolist() == [[k, min(k + 3, 29)] for k in range(0, 30, 4)]
    assert c.held.all()
    sunk_ = c.scans[:, 0] >= 20
    np.testing.assert_allclose(c.offset[sunk_, 2], -0.3, atol=0.05)
    assert np.all(np.abs(c.offset[c.scans[:, 1] < 16, 2]) < 0.05)
    assert c.scans[c.largest_dz(), 0] >= 20 and c.scan_span(c.largest_dz()).startswith("scans")
    # asked for tiles, the same map is cut into tiles; asked for 10 scans, 3 stretches
    assert regions_3d(built.points, truth, voxel=VOXEL, scan=built.scan, stretch=0).scans is None
    assert regions_3d(built.points, truth, voxel=VOXEL, scan=built.scan,
                      stretch=10).scans.tolist() == [[0, 9], [10, 19], [20, 29]]


def test_scans_that_do_not_start_at_0_and_a_stretch_too_small(truth, scan):
    """Scans numbered from 1000 (another program's): the stretches start at the first; a
    stretch that would cut the run into more than MOST_STRETCHES is refused in one line."""
    seen, poses = street_run(scan, 12, step=2.0)
    grid = ScanGrid(0.1)
    for index, (points, pose) in enumerate(zip(seen, poses, strict=True)):
        grid.add(points + pose[:3, 3], index)
    built = grid.map()
    c = regions_3d(built.points, truth, voxel=VOXEL, scan=built.scan + 1000.0)
    assert c.scans.tolist() == [[1000, 1003], [1004, 1007], [1008, 1011]]
    wide = built.scan * 1e4  # a run of 110,000 "scans"
    with pytest.raises(ValueError, match=r"--stretch-3d 4: the map's scans run from \d+ to "
                                         r"110000: 2\d{4} stretches of 4, more than 10000"):
        regions_3d(built.points, truth, voxel=VOXEL, scan=wide, stretch=4)
