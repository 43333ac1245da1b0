"""A cloud too large to hold is scored as a small one is: the streamed path (the PLY mapped onto
its file, the wall band found chunk by chunk, levelled on every k-th point) against the
in-memory path on the same generated cloud, with the limits made small."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import clouds, load_map
from pcmapq.raster import slice as slice_module
from testkit import synth
from testkit.files import in_map_frame, write_image_map

#: The scan's pose in the truth frame, as the shipped sample's.
POSE = Similarity2D(6.0, 8.0, float(np.radians(37.0)))


@pytest.fixture(scope="module")
def building(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A 3D scan of the plan in its own frame (turned, shifted, floor 0.8 m below the sensor)
    as a float32 binary PLY of about 440,000 points, and the plan as a PNG."""
    out = tmp_path_factory.mktemp("large")
    plan = synth.building_plan(seed=0)
    cloud = synth.lidar_cloud(in_map_frame(plan, POSE), seed=2) - [0.0, 0.0, 0.8]
    ply = out / "scan.ply"
    head = ("ply\nformat binary_little_endian 1.0\n"
            f"element vertex {len(cloud)}\nproperty float x\nproperty float y\n"
            "property float z\nend_header\n")
    ply.write_bytes(head.encode() + cloud.astype("<f4").tobytes())
    return ply, write_image_map(plan, out / "truth.png")


def test_streamed_cloud_scores_as_the_loaded_one(building: tuple[Path, Path],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    ply, truth = building
    loaded = evaluate(ply, truth)
    monkeypatch.setattr(clouds, "MAP_POINTS", 100_000)
    monkeypatch.setattr(clouds, "CHUNK", 30_000)
    monkeypatch.setattr(slice_module, "CHUNK", 60_000)
    assert not load_map(ply).points.flags.owndata  # mapped onto the file, not read
    streamed = evaluate(ply, truth)
    for name, result in loaded.detectors.items():
        q, got = result.matching, streamed.detectors[name].matching
        assert q.quality == pytest.approx(1.0, abs=0.05)
        assert got.quality == pytest.approx(q.quality, abs=0.01), name
        assert got.precision == pytest.approx(q.precision, abs=0.01), name
    for tf in (loaded.transform, streamed.transform):  # both at the known pose
        assert np.hypot(tf.tx - POSE.tx, tf.ty - POSE.ty) < 0.03
        assert abs(tf.yaw_deg - POSE.yaw_deg) < 0.1
    a, b = loaded.transform, streamed.transform
    assert np.hypot(a.tx - b.tx, a.ty - b.ty) < 0.01 and abs(a.yaw_deg - b.yaw_deg) < 0.05
    assert streamed.frames.map_levelling.floor_z_m == pytest.approx(
        loaded.frames.map_levelling.floor_z_m, abs=0.003)


def test_distances_3d_of_large_clouds_in_stripes_and_one_copy(monkeypatch):
    """Clouds of more than STRIPE_POINTS points are reduced in stripes of x, and their
    centroids handed to Open3D once: the same distances, in less than three float64 copies
    of a cloud (the one-pass table and two copies of the centroids took five)."""
    import tracemalloc

    from pcmapq.core import voxel_table, voxels
    from pcmapq.metrics.distances import distances_3d
    from testkit.street import street

    truth = street(0.0, 40.0, spacing=0.03, seed=0).astype(np.float32)
    moved = (street(0.0, 40.0, spacing=0.03, seed=0) + [0.02, 0.01, 0.0]).astype(np.float32)
    whole = distances_3d(moved, truth, 0.05)
    monkeypatch.setattr(voxels, "STRIPE_POINTS", 100_000, raising=False)
    monkeypatch.setattr(voxels, "STRIPE_WIDTH_POINTS", 60_000, raising=False)
    monkeypatch.setattr(voxel_table, "CHUNK", 4096)
    tracemalloc.start()
    try:
        striped = distances_3d(moved, truth, 0.05)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert striped == whole
    assert peak < 3 * 2 * truth.nbytes
