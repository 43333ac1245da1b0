"""Halmstad: robot maps against their building's layout, scale unknown. Every map's keypoint
residual under pcmapq's alignment (``bench/bench_scale.py``), then the full pipeline on one map
per building."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bench import bench_scale
from pcmapq.core.transform import Similarity2D
from pcmapq.io.occupancy import classify
from pcmapq.raster.draw import OCCUPIED
from pcmapq.report.text import number
from testkit.realdata.halmstad import (
    BROKEN_ANNOTATIONS,
    DARK,
    MAPS,
    PLAN_RESOLUTION,
    keypoint_residual,
    paths,
    pipeline,
    walls_read_occupied,
)
from testkit.runs import Run, f_at, yaw_error

from .common import ROS, Case, Record, Section, commonest_greys, header, q_p, row


@dataclass(frozen=True)
class Alignments:
    """``bench_scale.run``'s rows: (map, reference, pcmapq's similarity, median keypoint
    residual px, seconds)."""

    rows: list[tuple[str, Similarity2D, Similarity2D, float, float]]

    def summary(self) -> dict:
        return {name: {"x_px": round(got.tx, 6), "y_px": round(got.ty, 6),
                       "yaw_deg": round(got.yaw_deg, 6), "scale": round(got.scale, 6),
                       "residual_px": round(residual, 6)}
                for name, _, got, residual, _ in self.rows}


def cases(data: Path) -> list[Case]:
    return [Case("halmstad-alignment", lambda: Alignments(bench_scale.run(data / "halmstad"))),
            *(Case(f"halmstad-{name.lower()}", lambda n=name: pipeline(data, n)) for name in MAPS)]


def alignment_text(rows: list) -> str:
    """The bench's summary over every map."""
    residuals = np.array([r[3] for r in rows])
    scale_err = np.array([abs(r[2].scale / r[1].scale - 1.0) for r in rows])
    yaw_err = np.array([yaw_error(r[2].yaw_deg, r[1].yaw_deg) for r in rows])
    good = int((residuals < bench_scale.TARGET_PX).sum())
    worst = rows[int(np.argmax(residuals))][0]
    return (
        f"Alignment only (`bench/bench_scale.py`, both images in pixels, "
        f"{bench_scale.PIXELS.voxel:g} px voxels, {bench_scale.PIXELS.tolerance:g} px tolerance; "
        f"{', '.join(sorted(BROKEN_ANNOTATIONS))} skipped, its annotation is broken): "
        f"**{good} of {len(rows)} maps ({good / len(rows):.0%}) have a median keypoint "
        f"residual under {bench_scale.TARGET_PX:.0f} px** (target: "
        f"{100 * bench_scale.TARGET_SHARE:.0f} %). Residual median "
        f"{np.median(residuals):.1f} px, largest {residuals.max():.1f} px ({worst}); scale "
        f"within {100 * scale_err.max():.1f} % of the keypoint fit (median "
        f"{100 * np.median(scale_err):.1f} %), yaw within {yaw_err.max():.1f} deg (median "
        f"{np.median(yaw_err):.1f}); {np.median([r[4] for r in rows]):.1f} s a map.")


def pipeline_row(data: Path, name: str, run: Run) -> str:
    """One map's row of the pipeline's table."""
    r, tf = run.result, run.result.transform
    map_path, layout = paths(data, name)
    share = (f"{walls_read_occupied(layout):.2f} / "
             f"{walls_read_occupied(layout, bench_scale.WALL_GREY):.2f}")
    map_keys, layout_keys = bench_scale.keypoint_pairs(data / "halmstad", name,
                                                       name.rsplit("_", 1)[0])
    ref = bench_scale.fit_similarity(map_keys, layout_keys)
    return row([name, share, f"{tf.scale:.3f} ({ref.scale:.3f})",
                f"{tf.yaw_deg:.1f} ({ref.yaw_deg:.1f})",
                f"{keypoint_residual(r, map_path, map_keys, layout_keys):.1f}",
                number(r.alignment.fitness, 2), number(r.overlap.coverage, 2),
                number(r.overlap.confidence, 2), *(q_p(r, k) for k in ("harris", "hough", "sift")),
                number(r.distances.accuracy.mean), number(r.distances.completeness.mean),
                number(f_at(r, 0.2), 2), f"{run.seconds:.1f}"])


def section(data: Path, record: Record) -> Section:
    """The Halmstad maps against their layouts."""
    bench, *runs = (case.run(record) for case in cases(data))
    greys = np.arange(256)
    occupied = greys[classify(greys, 1, 1.0, np.zeros(256, bool), ROS) == OCCUPIED]
    first_map, first_layout = paths(data, MAPS[0])
    occ, unknown, free = commonest_greys(first_map)
    wall, outside, inside = commonest_greys(first_layout)
    return Section("\n".join([
        "## Halmstad: robot maps vs building layouts, scale unknown", "",
        f"`halmstad/maps/<B>/pseudo_occupancy/*.png` ({MAPS[0]}'s commonest greys: {occ} "
        f"occupied, {unknown} unknown, {free} free) against `maps/<B>/layout/<B>_layout.png` "
        f"(RGBA, opaque; {first_layout.stem}'s commonest greys: walls {wall} with "
        f"anti-aliased greys, outside {outside}, inside {inside}). The reference is the "
        "least-squares similarity of the annotated keypoint pairs.", "",
        alignment_text(bench.rows), "",
        "Full pipeline, `Settings(alignment=AlignmentConfig(scale=True), "
        f"truth=SourceConfig(resolution={PLAN_RESOLUTION}))` (no "
        "`force`), map image vs layout image, one map per building. The layout's walls are "
        "read as occupied by ROS's default thresholds, so no YAML is needed: column 2 is the "
        f"share of its pixels darker than {DARK} (wall cores) and than "
        f"{bench_scale.WALL_GREY} (the bench's wall mask) that the loader marks occupied; "
        f"greys up to {occupied.max():.0f} count (p > {ROS.occupied_thresh}), the "
        f"lighter anti-aliased edge pixels ({occupied.max() + 1:.0f}-"
        f"{bench_scale.WALL_GREY - 1}) are read unknown, a one-pixel thinning of no "
        "consequence. Both images have no resolution: the layout is taken at "
        f"{PLAN_RESOLUTION} m per pixel, so lengths are metres only under that assumption. "
        "Scale: layout pixels per map pixel; keypoint residual: median, layout pixels, of the "
        "annotated map keypoints carried by the pipeline's alignment; q / p: quality / "
        "precision.", "",
        header(["map", f"occupied: grey < {DARK} / < {bench_scale.WALL_GREY}", "scale (ref)",
                "yaw deg (ref)", "keypoint residual px", "fitness", "coverage", "confidence",
                "Harris q / p", "Hough q / p", "SIFT q / p", "acc mean m", "comp mean m",
                "F@0.2", "s"]),
        *(pipeline_row(data, name, run) for name, run in zip(MAPS, runs, strict=True)),
    ]))
