"""Write the shipped sample: a building plan as a ROS map (truth.png + truth.yaml), a 3D
LiDAR-like scan of the same building in the robot's own frame (scan.ply), and a ROS 2
recording of the maps a SLAM system would publish while exploring it (run/).

The scan differs from the plan in known ways, so the sample's result can be checked by eye:
it is turned and shifted (p_truth = R(yaw) * p_scan + t with the values in SCAN_POSE), one wall
is moved by 0.3 m, furniture-like boxes stand in the rooms, and it has noise and outliers. The
recording's /map grows from west to east every 10 s in a frame of its own (RUN_ORIGIN); from
DRIFT_AT seconds on, what it adds lies DRIFT_PX cells north of where it should.

    python -m tools.make_sample [OUT_DIR]     (default: data/sample)
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import open3d as o3d

from pcmapq.core.cells import UNKNOWN
from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.io import load_map
from testkit import synth
from testkit.recordings import write_recording

#: The scan frame's pose in the truth frame: x, y metres, yaw degrees.
SCAN_POSE = (6.0, 8.0, 37.0)
RESOLUTION = 0.05
MOVED_WALL, MOVED_BY = 5, (0.3, 0.0)  # the room wall at x = 8.0 m moves to 8.3 m
#: The recording: its maps' origin (x, y metres, yaw radians), one map every STEP_S seconds,
#: the drift from DRIFT_AT seconds on, cells north.
RUN_ORIGIN, STEP_S, MAPS, DRIFT_AT, DRIFT_PX = (2.0, -3.0, 0.5), 10.0, 7, 30.0, 14


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    plan = synth.building_plan(seed=0)
    grid = synth.plan_grid(plan, RESOLUTION)
    cv2.imwrite(str(out / "truth.png"), synth.render(plan, grid))
    ox, oy, _ = grid.origin
    (out / "truth.yaml").write_text(
        "image: truth.png\n"
        f"resolution: {RESOLUTION}\n"
        f"origin: [{ox:.3f}, {oy:.3f}, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")

    seen = synth.clutter(synth.move_wall(plan, MOVED_WALL, MOVED_BY), count=6, seed=3)
    cloud = synth.lidar_cloud(seen, spacing=0.07, noise=0.01, seed=1)
    x, y, yaw = SCAN_POSE
    to_scan = Similarity2D(x, y, np.radians(yaw)).inverse()
    cloud[:, :2] = to_scan.apply(cloud[:, :2])
    cloud[:, 2] -= 0.8  # the sensor's frame: floor 0.8 m below it
    pcd = o3d.t.geometry.PointCloud(o3d.core.Tensor(cloud.astype(np.float32)))
    o3d.t.io.write_point_cloud(str(out / "scan.ply"), pcd)
    write_run(out)
    print(f"wrote {out}/truth.png, truth.yaml, scan.ply ({len(cloud)} points), run/; "
          f"scan pose in truth frame: x {x} m, y {y} m, yaw {yaw} deg")


def write_run(out: Path) -> None:
    """The recording: the truth's cells published as a growing /map (west to east), drifted
    north from DRIFT_AT seconds on, zstd-compressed messages in a ROS 2 MCAP bag."""
    import shutil

    truth = load_map(out / "truth.yaml")
    rows, cols = truth.state.shape
    grid = MetricGrid(truth.grid.resolution, RUN_ORIGIN, (rows, cols))
    edges = np.linspace(0.45 * cols, cols, MAPS).astype(int)
    drift_from = edges[int(DRIFT_AT / STEP_S) - 1]
    maps = []
    for k, edge in enumerate(edges):
        state = truth.state.copy()
        if k * STEP_S >= DRIFT_AT:
            state[:, drift_from:] = np.roll(state[:, drift_from:], -DRIFT_PX, axis=0)
        state[:, edge:] = UNKNOWN
        maps.append((k * STEP_S, state, grid))
    shutil.rmtree(out / "run", ignore_errors=True)
    write_recording(out / "run", maps, "ros2-mcap", compress=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("data/sample"))
