"""A large pair of 3D clouds (issue 57): :mod:`testkit.town3d`'s town as the truth and its
drifted map, written as binary little-endian float32 x, y, z PLY (12 bytes a point).

    python -m bench.large_3d OUT [--points 10]   writes OUT/truth.ply and OUT/map.ply

The town does not grow with the points (3 x 2 blocks of 36 m): 10 M points are about 1,000 a
square metre, 3 cm apart; 50 M about 5,000, 1.4 cm apart, a dense mobile mapping or survey scan.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from testkit.town3d import MAP_SEED, TRUTH_SEED, clouds


def write_cloud(path: Path, points: int, seed: int, as_map: bool) -> Path:
    """Write one cloud of the pair as a binary float32 PLY."""
    header = ("ply\nformat binary_little_endian 1.0\ncomment pcmapq bench large_3d\n"
              f"element vertex {points}\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n")
    with path.open("wb") as f:
        f.write(header.encode("ascii"))
        for part in clouds(points, seed, as_map):
            f.write(part.tobytes())
    return path


def write_case(out: Path, points: int) -> tuple[Path, Path]:
    """Write ``out/map.ply`` and ``out/truth.ply`` of ``points`` points each."""
    out.mkdir(parents=True, exist_ok=True)
    return (write_cloud(out / "map.ply", points, MAP_SEED, True),
            write_cloud(out / "truth.ply", points, TRUTH_SEED, False))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--points", type=float, default=10.0, help="millions a cloud")
    args = parser.parse_args()
    write_case(args.out, int(args.points * 1e6))


if __name__ == "__main__":
    main()
