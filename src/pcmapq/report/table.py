"""The terminal view of a Result: a verdict in words, the alignment, one row per detector (its
scores and counts, then its displacements), the distances and a legend. Fits the console's
width with no value cut: lines break only between whole values, and a table too wide for the
console is printed as one stacked block per detector instead."""

from __future__ import annotations

from rich import box
from rich.console import Console
from rich.table import Table

from pcmapq.core.stats import FIELDS, Stats
from pcmapq.core.words import count, length
from pcmapq.report.structures import displacement_stats, structure_scores, thresholds
from pcmapq.report.structures import notes as structure_notes
from pcmapq.report.text import (
    LEGEND,
    map_3d_parts,
    metres,
    number,
    relief_parts,
    score,
    verdict,
    words,
    wrap,
)
from pcmapq.results.result import DetectorResult, Result

#: Width of the labels of the key-value lines, characters.
LABEL = 12
#: The score table's columns: header, and the figure of a detector.
SCORE_COLUMNS = ("quality", "precision", "f1", "truth\nfeatures", "matched\ntruth",
                 "map\nfeatures", "matched\nmap")
#: The displacement table's columns (the Stats fields; count is the number of pairs).
DISPLACEMENT_COLUMNS = ("pairs", *FIELDS[1:])


def print_table(result: Result, console: Console) -> None:
    """Print the verdict, the alignment, the per-detector scores and displacements, the
    distances and the legend on ``console`` (metres, degrees), within its width."""
    width = console.width
    _lines(console, words(verdict(result), width))
    console.print()
    for label, parts in _summary(result):
        _field(console, label, _values(console, parts))
    if result.detectors or result.structures is not None:
        console.print()
        _scores(console, result)
        console.print()
        _displacements(console, result)
    console.print()
    for label, parts in _distances(result) + _noref(result):
        _field(console, label, _values(console, parts))
    for i, note in enumerate(result.notes() + structure_notes(result)):
        _field(console, "notes" if i == 0 else "", words(note, width - LABEL - 1))
    console.print()
    _lines(console, words(LEGEND, width))


def score_row(det: DetectorResult) -> tuple[str, ...]:
    """A detector's figures in :data:`SCORE_COLUMNS` order: quality, precision and f1 ('n/a'
    when undefined), then the counts of strong features (quality = matched truth / truth
    features, precision = matched map / map features)."""
    m = det.matching
    return (score(m.quality), score(m.precision), score(m.f1), str(m.truth_features),
            str(m.matched), str(m.map_features), str(m.matched_map))


def displacement_row(stats: Stats) -> tuple[str, ...]:
    """A detector's displacement statistics in :data:`DISPLACEMENT_COLUMNS` order, metres."""
    return (str(stats.count), *(number(getattr(stats, k)) for k in FIELDS[1:]))


def _summary(result: Result) -> list[tuple[str, list[str]]]:
    """The inputs, the alignment and the footprint as (label, values) lines."""
    a, tf = result.alignment, result.transform
    lines = [
        ("map", [str(result.map_path), result.map_kind]),
        ("truth", [str(result.truth_path), result.truth_kind,
                   f"{result.grid.resolution:g} m cells"]),
        ("alignment", [f"x {tf.tx:.3f} m", f"y {tf.ty:.3f} m", f"yaw {tf.yaw_deg:.2f} deg",
                       f"scale {tf.scale:.4f}", f"map -> truth by {a.method}",
                       f"fitness {a.fitness:.3f} within {a.tolerance_m:g} m",
                       f"rmse {a.rmse_m:.3f} m",
                       f"confidence {result.overlap.confidence:.2f}",
                       result.overlap.verdict]),
        ("footprint", [f"{result.footprint_rule}",
                       f"coverage {result.overlap.coverage:.3f}",
                       "scored against the whole truth" if result.full
                       else "truth features outside it not counted"]),
    ]
    c = result.consistency
    if c is not None and (k := c.largest()) is not None:
        x, y = c.centre[k]
        lines.append(("regions", [f"largest offset {c.offset_m[k]:.3f} m",
                                  f"turn {abs(c.turn_deg[k]):.2f} deg",
                                  f"at ({x:.1f}, {y:.1f}) m",
                                  f"{count(len(c.points), 'region')} of {length(c.tile_m)}",
                                  f"fitness {c.global_fitness():.3f} as placed",
                                  f"{c.local_fitness():.3f} each fitted alone"]))
    if result.registration_3d is not None:
        reg = result.registration_3d
        lines.append(("3D", [f"registration fitness {reg.fitness:.3f}",
                             f"rmse {reg.rmse_m:.3f} m"]))
    if parts := relief_parts(result):
        lines.append(("3D regions", parts))
    return lines


def _distances(result: Result) -> list[tuple[str, list[str]]]:
    """The wall distances (and the 3D ones when both inputs are 3D clouds) as lines."""
    d = result.distances
    cells = f"{result.grid.resolution:g} m plan cells"
    lines = [("accuracy", _stats_parts(d.accuracy, f"map -> truth on {cells}")),
             ("completeness", _stats_parts(d.completeness, "truth -> map")),
             ("F-score", [f"F@{s.tau_m:g} m {s.f:.3f}" for s in d.fscores]
              + [f"Chamfer {metres(d.chamfer_m)}"])]
    if result.distances_3d is not None:
        d3 = result.distances_3d
        voxel = (result.settings or {}).get("raster", {}).get("cloud_resolution")
        voxels = "3D" if voxel is None else f"{voxel:g} m voxels, 3D"
        lines += [("3D accuracy", _stats_parts(d3.accuracy, f"map -> truth on {voxels}")),
                  ("3D complete", _stats_parts(d3.completeness, "truth -> map, 3D")),
                  ("3D", [f"Chamfer {metres(d3.chamfer_m)}"])]
    if result.map_3d is not None:
        lines.append(("3D map", map_3d_parts(result.map_3d, result.settings)))
    return lines


def _noref(result: Result) -> list[tuple[str, list[str]]]:
    """Each input's no-reference figures (``pcmapq inspect``'s) as a line, units in each."""
    if result.noref is None:
        return []
    return [(f"{side} noref", _noref_parts(result.noref[side])) for side in ("map", "truth")]


def _noref_parts(figures: dict) -> list[str]:
    cloud, grid = figures["cloud"], figures["grid"]
    if cloud is not None:
        return [f"MME {_g(cloud['mme'])}" + (" nats" if cloud["mme"] is not None else ""),
                f"MPV {_g(cloud['mpv'])}" + (" m²" if cloud["mpv"] is not None else ""),
                f"MOM {_g(cloud['mom'])}" + (" m²" if cloud["mom"] is not None else ""),
                f"within {cloud['radius_m']:g} m"]
    parts = [f"{count(grid['occupied_cells'], 'occupied cell')} of {grid['resolution_m']:g} m"]
    if grid["occupied_free_ratio"] is not None:
        parts.append(f"occupied/free {grid['occupied_free_ratio']:.4f}")
    parts.append(count(grid["corners"], "corner"))
    if grid["enclosed_areas"] is not None:
        parts.append(count(grid["enclosed_areas"], "enclosed area"))
    return parts


def _g(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.4g}"


def _stats_parts(stats: Stats, direction: str) -> list[str]:
    """A distance's statistics as 'mean 0.127 m' pieces, with its direction."""
    return [direction, f"mean {metres(stats.mean)}",
            *(f"{k} {metres(getattr(stats, k))}" for k in ("median", "rmse", "std", "p95",
                                                           "max"))]


def _scores(console: Console, result: Result) -> None:
    """Quality, precision, f1 and the four counts per detector."""
    rows = {name: score_row(det) for name, det in result.detectors.items()}
    rows.update(structure_scores(result))  # beside them: the 3D structures
    also = f"; {thresholds(result)}" if result.structures is not None else ""
    _table_or_blocks(
        console, _table(SCORE_COLUMNS, rows),
        f"features matched within {result.threshold:g} m (counts of strong features; "
        f"quality = matched truth / truth features, precision = matched map / map features)"
        f"{also}",
        f"features matched within {result.threshold:g} m",
        {name: [f"quality {q} ({matched}/{truth} truth)",
                f"precision {p} ({matched_map}/{map_} map)", f"f1 {f1}"]
         for name, (q, p, f1, truth, matched, map_, matched_map) in rows.items()})


def _displacements(console: Console, result: Result) -> None:
    """The displacement statistics of each detector's matched pairs, metres."""
    rows = {name: displacement_row(det.displacement_stats())
            for name, det in result.detectors.items()}
    rows.update((name, displacement_row(stats))
                for name, stats in displacement_stats(result).items())
    _table_or_blocks(
        console, _table(DISPLACEMENT_COLUMNS, rows),
        "displacement from truth feature to map feature over the matched pairs (every pair, "
        "whichever of its features are counted), metres",
        "displacement of the matched pairs",
        {name: [count(int(pairs), "pair")] + [f"{k} {v}" + (" m" if v != "-" else "")
                                     for k, v in zip(FIELDS[1:], values, strict=True)]
         for name, (pairs, *values) in rows.items()})


def _table_or_blocks(console: Console, table: Table, title: str, short_title: str,
                     blocks: dict[str, list[str]]) -> None:
    """``table`` under ``title`` when it fits the console's width; else ``short_title`` and
    one block of ``blocks``' values per row name, broken between values."""
    if _fits(console, table):
        _lines(console, words(title, console.width))
        console.print(table)
        return
    _lines(console, words(short_title, console.width))
    for name, parts in blocks.items():
        _field(console, name, _values(console, parts))


def _table(columns: tuple[str, ...], rows: dict[str, tuple[str, ...]]) -> Table:
    """A right-aligned table, one row per detector, no vertical rules, no cell wrapped."""
    table = Table(box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False,
                  padding=(0, 0, 0, 1))
    table.add_column("detector", no_wrap=True)
    for col in columns:
        table.add_column(col, justify="right", no_wrap=True)
    for name, row in rows.items():
        table.add_row(name, *row)
    return table


def _fits(console: Console, table: Table) -> bool:
    """Whether ``table`` shows whole on ``console``, every cell on one line."""
    unbounded = console.options.update_width(10_000)
    return console.measure(table, options=unbounded).maximum <= console.width


def _field(console: Console, label: str, lines: list[str]) -> None:
    """Lines of values under a label: the label's column, then the lines one under another
    (each at most ``console.width - LABEL - 1`` wide, see :func:`_values`)."""
    first, *rest = lines
    _lines(console, [f"{label:<{LABEL}} {first}", *(" " * (LABEL + 1) + line for line in rest)])


def _values(console: Console, parts: list[str]) -> list[str]:
    """Values joined by commas in lines that fit beside the labels, broken between values."""
    return wrap(parts, console.width - LABEL - 1)


def _lines(console: Console, lines: list[str]) -> None:
    """Print lines as they are: no markup, no highlighting, no rewrapping."""
    for line in lines:
        console.print(line, markup=False, highlight=False, soft_wrap=True)
