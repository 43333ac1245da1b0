"""The large-grid case of issue 10: a campus of copies of one building as the truth image, and
the same campus seen by a robot as the map image: turned, shifted, its walls drawn from points
with Gaussian noise. Both are ``size`` x ``size`` cells of 0.05 m with their map_server YAML.

    python -m bench.large_grid OUT [--size 8000]   writes OUT/truth.png, OUT/map.png (+ YAML)

``write_case`` returns the known map -> truth transform, for benchmarks and checks.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from pcmapq.core.grid import MetricGrid
from pcmapq.core.transform import Similarity2D
from pcmapq.io.writers import write_ros_map
from pcmapq.raster.draw import points_to_grid, polygon_cells
from testkit import synth

RESOLUTION = 0.05
#: The map's pose in the truth frame (p_truth = R(yaw) p_map + t).
KNOWN = Similarity2D(31.0, -17.0, float(np.radians(-12.0)))
NOISE = 0.03
GAP = 4.0


def centred_grid(xy: np.ndarray, size: int, resolution: float = RESOLUTION) -> MetricGrid:
    """A ``size`` x ``size`` grid whose centre is the centre of the points' bounding box."""
    centre = 0.5 * (xy.min(axis=0) + xy.max(axis=0))
    corner = centre - 0.5 * size * resolution
    return MetricGrid(resolution, (float(corner[0]), float(corner[1]), 0.0), (size, size))


def campus_for(size: int, resolution: float = RESOLUTION) -> np.ndarray:
    """The largest campus (wall segments, metres) that fits ``size`` cells with a 1 m margin."""
    span = size * resolution - 2.0 + GAP
    return synth.campus(max(1, int(span // (24.0 + GAP))), max(1, int(span // (16.0 + GAP))),
                        gap=GAP)


def write_case(out: Path, size: int = 8000, tf: Similarity2D = KNOWN,
               noise: float = NOISE, seed: int = 0) -> Similarity2D:
    """Write ``out/truth.png`` and ``out/map.png`` (each with its YAML); returns the map -> truth
    transform. The map's walls are points on both wall faces every 0.02 m with ``noise`` metres
    of Gaussian noise, a cell occupied where one falls; free space is the campus's box."""
    out.mkdir(parents=True, exist_ok=True)
    walls = campus_for(size)
    truth_grid = centred_grid(walls.reshape(-1, 2), size)
    write_ros_map(out / "truth.png", synth.render(walls, truth_grid), RESOLUTION,
                  truth_grid.origin[:2])
    seen = synth.transform_segments(walls, tf.inverse())
    map_grid = centred_grid(seen.reshape(-1, 2), size)
    lo, hi = walls.reshape(-1, 2).min(axis=0), walls.reshape(-1, 2).max(axis=0)
    box = tf.inverse().apply(np.array([lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]))
    image = np.full(map_grid.shape, synth.UNKNOWN, np.uint8)
    image[polygon_cells(box, map_grid)] = synth.FREE
    image[points_to_grid(synth.wall_points(seen, noise=noise, seed=seed), map_grid)] = \
        synth.OCCUPIED
    write_ros_map(out / "map.png", image, RESOLUTION, map_grid.origin[:2])
    return tf


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--size", type=int, default=8000)
    args = parser.parse_args()
    tf = write_case(args.out, args.size)
    print(f"known map -> truth: x {tf.tx} m, y {tf.ty} m, yaw {tf.yaw_deg:.1f} deg")


if __name__ == "__main__":
    main()
