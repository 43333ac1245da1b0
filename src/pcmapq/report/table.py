"""The terminal view of a Result: the alignment and one row per detector."""

from __future__ import annotations

from rich.console import Console
from rich.table import Table

from pcmapq.report.text import number, score
from pcmapq.result import Result


def print_table(result: Result, console: Console) -> None:
    """Print the alignment and the per-detector qualities (metres, degrees)."""
    a = result.alignment
    tf = result.transform
    console.print(
        f"[bold]{result.map_path}[/] -> [bold]{result.truth_path}[/]  "
        f"x {tf.tx:.3f} m  y {tf.ty:.3f} m  yaw {tf.yaw_deg:.2f} deg  scale {tf.scale:.4f}  "
        f"fitness {a.fitness:.3f} (within {a.tolerance_m} m)  rmse {a.rmse_m:.3f} m  "
        f"coverage {result.overlap.coverage:.3f} (footprint: {result.footprint_rule})  "
        f"confidence {result.overlap.confidence:.2f}"
        + ("  (scored against the whole truth)" if result.full else ""))
    table = Table(title=f"feature matching within {result.threshold} m")
    for col in ("detector", "quality", "precision", "f1", "truth", "map", "matched"):
        table.add_column(col, justify="right")
    for col in ("mean m", "median m", "rmse m", "max m"):
        table.add_column(f"disp. {col}", justify="right")
    for name, det in result.detectors.items():
        m = det.matching
        stats = det.displacement_stats()
        table.add_row(name, score(m.quality), score(m.precision), score(m.f1),
                      str(m.truth_features), str(m.map_features), str(m.matched),
                      *(number(getattr(stats, k)) for k in ("mean", "median", "rmse", "max")))
    console.print(table)
    for line in result.notes():
        console.print(line, highlight=False)
    if result.registration_3d is not None and result.distances_3d is not None:
        reg, d3 = result.registration_3d, result.distances_3d
        console.print(f"3D registration: fitness {reg.fitness:.3f}, rmse {reg.rmse_m:.3f} m; "
                      f"3D accuracy mean {number(d3.accuracy.mean)} m, completeness mean "
                      f"{number(d3.completeness.mean)} m, Chamfer {number(d3.chamfer_m)} m")
    d = result.distances
    f = "  ".join(f"F@{s.tau_m:g} m {s.f:.3f}" for s in d.fscores)
    console.print(f"distances: accuracy mean {number(d.accuracy.mean)} m, completeness mean "
                  f"{number(d.completeness.mean)} m, Chamfer {number(d.chamfer_m)} m  {f}")
