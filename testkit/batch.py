"""A small batch with known answers: a truth, maps of it seen from other poses, a map file that
is not an image, and the manifest naming them."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from pcmapq.core.transform import Similarity2D

from . import synth
from .files import in_map_frame, write_image_map

#: name, map pose in the truth frame (x m, y m, yaw deg), manifest cells of the row's options.
MAPS = [("straight", (0.0, 0.0, 0.0), {}),
        ("turned", (0.4, -0.3, 8.0), {"threshold": "0.3"}),
        ("scaled", (-0.2, 0.5, -5.0), {"scale": "auto", "footprint": "walls"})]


def write_inputs(folder: Path) -> Path:
    """A small truth (12 m x 8 m plan), three maps of it seen from other poses and a map file
    that is not an image, with a manifest (``runs.csv``, relative paths) naming them, written
    in ``folder``; the folder."""
    (folder / "maps").mkdir()
    plan = synth.building_plan(0, 12.0, 8.0)
    write_image_map(plan, folder / "truth.png")
    for i, (name, (x, y, yaw), _) in enumerate(MAPS):
        seen = synth.move_wall(plan, 2, (0.1 * i, 0.0))
        write_image_map(in_map_frame(seen, Similarity2D(x, y, np.radians(yaw))),
                        folder / "maps" / f"{name}.png")
    (folder / "maps" / "broken.png").write_bytes(b"not a png at all")
    (folder / "maps" / "broken.yaml").write_text("image: broken.png\nresolution: 0.05\n"
                                                 "origin: [0, 0, 0]\n")
    columns = ["name", "map", "truth", "threshold", "scale", "footprint"]
    rows = [{"name": n, "map": f"maps/{n}.png", "truth": "truth.png", **cells}
            for n, _, cells in MAPS]
    rows.insert(2, {"name": "broken", "map": "maps/broken.png", "truth": "truth.png"})
    with open(folder / "runs.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, columns)
        writer.writeheader()
        writer.writerows(rows)
    return folder
