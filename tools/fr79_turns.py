"""The Freiburg 079 SLAM map turned by known angles and scored against itself (known answers on
a real map's texture): the table of docs/validation.md, "Freiburg 079 SLAM map".

    python tools/fr79_turns.py [--data ../shared/data] [--turns 0,90,123,30]

The map (0.05 m per pixel assumed) is turned about its origin by each angle with
nearest-neighbour sampling, shifted, and aligned back by ``pcmapq.pipeline.evaluate``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

from pcmapq.grid import MetricGrid
from pcmapq.io.writers import write_ros_map
from pcmapq.pipeline import evaluate
from pcmapq.report.text import score
from pcmapq.transform import Similarity2D

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
#: Assumed resolution of the SLAM map, metres per pixel.
RESOLUTION = 0.05
#: Unknown grey of the turned map's border (map_server reads 153 as unknown).
UNKNOWN_GREY = 153


def turned(image: np.ndarray, tf: Similarity2D, folder: Path) -> Path:
    """The map image moved by ``tf`` (truth -> map frame), written as a ROS map."""
    rows, cols = image.shape
    src = MetricGrid(RESOLUTION, (0.0, 0.0, 0.0), (rows, cols))
    corners = src.pixels_to_xy([[0, 0], [cols, 0], [0, rows], [cols, rows]])
    dst = MetricGrid.covering(tf.apply(corners), RESOLUTION)
    m = src.xy_to_pixel_matrix() @ tf.inverse().matrix @ dst.pixel_to_xy_matrix()
    out = cv2.warpAffine(image, m[:2], dst.shape[::-1], borderValue=UNKNOWN_GREY,
                         flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP)
    return write_ros_map(folder / f"turned_{tf.yaw_deg:.0f}.png", out, RESOLUTION,
                         dst.origin[:2])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA)
    parser.add_argument("--turns", default="0,90,123,30")
    args = parser.parse_args(argv)
    source = args.data / "floorplans" / "freiburg_building79.png"
    if not source.is_file():
        print(f"{source}: absent (real data lives in ../shared/data)", file=sys.stderr)
        return 2
    image = cv2.imread(str(source), cv2.IMREAD_GRAYSCALE)
    print("| turn | recovered yaw | Harris | Hough | SIFT |\n| --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        truth = write_ros_map(Path(tmp) / "fr79.png", image, RESOLUTION)
        for deg in (float(t) for t in args.turns.split(",")):
            tf = Similarity2D(-3.0, 21.0, np.radians(deg))
            result = evaluate(turned(image, tf, Path(tmp)), truth)
            cells = [f"{deg:g} deg", f"{result.transform.yaw_deg:.3f}"]
            for det in result.detectors.values():
                m = det.matching
                cells.append(f"{m.truth_features} / {m.map_features}, "
                             f"{score(m.quality, 2)} / {score(m.precision, 2)}")
            print("| " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
