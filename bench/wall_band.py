"""The picture of docs/method.md, "Features": a corner of the synthetic plan drawn three ways
(top) and what the detectors see of each (bottom), with the Harris corners.

    python -m bench.wall_band [docs/img/wall_band.png]
"""

from __future__ import annotations

import sys
from pathlib import Path

from bench.validation.drawings import plan_variants
from pcmapq.features import detect, walls_of
from testkit import synth

#: The drawings shown, by title and variant name.
SHOWN = {"1 cell at 0.025 m": "1 cell at 0.025 m", "6 cells (0.3 m) at 0.05 m": "6 cells at 0.05 m",
         "double outline at 0.025 m": "double outline at 0.025 m"}
#: x0, x1, y0, y1 metres: rooms, a corridor, pillars.
WINDOW = (11.0, 21.5, 8.0, 15.0)


def figure(path: Path) -> None:
    """Save the picture at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    variants = plan_variants(synth.building_plan(0))
    fig, axes = plt.subplots(2, 3, figsize=(10, 6.4), constrained_layout=True)
    for col, (title, key) in enumerate(SHOWN.items()):
        occ, grid = variants[key]
        walls = walls_of(occ, grid)
        corners = detect("harris", occ, grid)
        for row, (img, g) in enumerate(((occ.astype(float), grid), (walls.image, walls.grid))):
            ax = axes[row, col]
            x0, y0 = g.origin[:2]
            w, h = g.size_m
            ax.imshow(img, cmap="Greys", vmin=0, vmax=1, extent=(x0, x0 + w, y0, y0 + h),
                      interpolation="nearest")
            if row == 1:
                xy = corners.xy[corners.strong]
                ax.plot(xy[:, 0], xy[:, 1], "o", mfc="none", mec="tab:red", ms=7)
            ax.set_xlim(WINDOW[0], WINDOW[1])
            ax.set_ylim(WINDOW[2], WINDOW[3])
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(title if row == 0 else "what the detectors see", fontsize=10)
    fig.savefig(path, dpi=90)
    plt.close(fig)


if __name__ == "__main__":
    figure(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("docs/img/wall_band.png"))
