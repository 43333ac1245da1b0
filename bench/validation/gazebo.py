"""Gazebo: a SLAM map of unknown pixel size against the rendered world (529 px per metre): scale,
accuracy next to the published figures, the footprint rule, time and memory per step."""

from __future__ import annotations

from pathlib import Path

import cv2

from testkit.realdata.gazebo import BOUND_M, MAP, RESOLUTION, SETTINGS, TRUTH, run

from .common import Case, Record, Section, cm, qualities

#: Published map-to-truth nearest-occupied distances of this pair, cm, after per-axis rescaling
#: of the map to the truth's size, and their sample count (../shared/README.md, from the data
#: set's source).
PUBLISHED_CM = {"mean": 4.06, "median": 3.15, "std": 3.64, "max": 18.5}
PUBLISHED_SAMPLES = 56_605


def cases(data: Path) -> list[Case]:
    return [Case("gazebo", lambda: run(data)),
            Case("gazebo-known-footprint", lambda: run(data, "known"))]


def section(data: Path, record: Record) -> Section:
    """The pair's scale, distances against the published ones, the known-cells footprint,
    time and memory."""
    main, known = (case.run(record) for case in cases(data))
    r, tf = main.result, main.result.transform
    acc, comp = r.distances.accuracy, r.distances.completeness
    k, kc = known.result, known.result.distances.completeness
    rows, cols = r.grid.shape
    map_rows, map_cols = cv2.imread(str(data / "gazebo" / MAP), cv2.IMREAD_GRAYSCALE).shape
    cell_mm = RESOLUTION * 1000
    steps = ", ".join(f"{step} {s:.1f} s" for step, s in main.steps.items())
    longest = sorted(main.steps, key=main.steps.__getitem__)[-2:][::-1]
    pub = PUBLISHED_CM
    met = acc.mean is not None and acc.mean < BOUND_M
    margin = SETTINGS.footprint.margin
    return Section("\n".join([
        "## Gazebo: SLAM map of unknown pixel size vs the rendered world", "",
        f"`gazebo/{MAP}` ({map_cols} x {map_rows}) against `gazebo/{TRUTH}` ({cols} x {rows}, "
        f"{1 / RESOLUTION:.0f} px per metre, {cell_mm:.3f} mm cells): "
        f"`Settings(truth=SourceConfig(resolution=1/{1 / RESOLUTION:.0f}), "
        "alignment=AlignmentConfig(scale=True))`, one scale for both "
        "axes (`tests/realdata/test_validation.py` checks the bounds).", "",
        f"Alignment: scale {tf.scale:.4f} (a map pixel is {tf.scale * cell_mm:.3f} mm; the "
        f"images' size ratios are {cols / map_cols:.4f} across, {rows / map_rows:.4f} down), "
        f"yaw {tf.yaw_deg:.3f} deg, fitness {r.alignment.fitness:.3f}, inlier RMSE "
        f"{cm(r.alignment.rmse_m)} cm; coverage {r.overlap.coverage:.2f}, confidence "
        f"{r.overlap.confidence:.2f}.", "",
        "| map -> truth distance [cm] | mean | median | RMSE | p95 | std | max | samples |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
        f"| pcmapq accuracy (one scale) | {cm(acc.mean)} | {cm(acc.median)} | {cm(acc.rmse)} | "
        f"{cm(acc.p95)} | - | - | {acc.count} cells |",
        f"| published (per-axis rescaling) | {pub['mean']:.2f} | {pub['median']:.2f} | - | - | "
        f"{pub['std']:.2f} | {pub['max']:.1f} | {PUBLISHED_SAMPLES:,} |", "",
        f"Completeness (truth -> map) mean {cm(comp.mean)} cm, median {cm(comp.median)} cm, "
        f"p95 {cm(comp.p95)} cm; qualities (q / precision): {qualities(r)}. "
        f"Bound: mean accuracy < {100 * BOUND_M:.0f} cm: {'met' if met else 'NOT met'}. "
        "The published figures are the data set's (../shared/README.md).", "",
        f"The SLAM map is binary (no unknown value), so its footprint is the area its walls "
        f"enclose (`--footprint auto`: {r.footprint_rule}, see docs/method.md). With its known "
        f"cells, i.e. its whole rectangle (`--footprint known`), coverage is "
        f"{k.overlap.coverage:.2f}, agreement {k.overlap.agreement:.2f} "
        f"({r.overlap.agreement:.2f} with the walls), completeness mean {cm(kc.mean)} cm, "
        f"median {cm(kc.median)} cm, p95 {cm(kc.p95)} cm, and the qualities {qualities(k)}: "
        "the truth's wall along the image's lower edge, which the map never shows, counts as "
        f"missing ({known.seconds:.1f} s; rasterising "
        f"{known.steps.get('rasterising', 0.0):.1f} s).", "",
        f"Time {main.seconds:.1f} s ({steps}); peak memory {main.peak_gb:.2f} GB (the process "
        f"during the run). The truth grid has {rows * cols / 1e6:.0f} M cells: the "
        f"footprint's {margin} m margin is {margin / RESOLUTION:.0f} cells, grown by an exact "
        f"distance transform (`pcmapq.raster.footprint.grow`). The longest steps: "
        f"{longest[0]} and {longest[1]}.",
    ]))
