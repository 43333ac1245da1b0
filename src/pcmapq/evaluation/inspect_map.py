"""``pcmapq inspect``: how good a map is without a ground truth. A 3D cloud (or scans placed at
their poses) gets MME, MPV and MOM (:mod:`pcmapq.metrics.noref`, as map-metrics defines them); a
2D map gets the occupancy figures of :mod:`pcmapq.metrics.noref2d`. docs/metrics.md says what
each figure can and cannot tell.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq import __version__
from pcmapq.core.stats import significant
from pcmapq.core.words import count
from pcmapq.evaluation.noref_figures import input_figures
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.settings import NoRefConfig


def inspect_map(source: OccupancyMap | PointMap, config: NoRefConfig = NoRefConfig(),
                orth_subset: Sequence[np.ndarray] | None = None,
                command: str = "") -> dict[str, Any]:
    """The no-reference figures of one map as a JSON-ready record: ``cloud`` (3D clouds: MME
    nats, MPV and MOM m^2) or ``grid`` (images and 2D clouds), the other None
    (:func:`pcmapq.evaluation.noref_figures.input_figures`). ``orth_subset``: MOM's planes in
    the map's frame (None: extracted from the map)."""
    return {"pcmapq": {"version": __version__, "command": command},
            "map": {"path": str(source.path), "kind": source.kind},
            **input_figures(source, config, None if orth_subset is None else list(orth_subset))}


def to_json(record: dict[str, Any]) -> str:
    """The record as strict JSON (no NaN or infinity; figures to six significant digits), as
    ``eval --json`` writes its ``noref`` block."""
    return json.dumps(significant(record), indent=2, allow_nan=False) + "\n"


def _se(value: float | None) -> str:
    """`` ± standard error`` of a sampled mean, or ''."""
    return "" if value is None else f" ± {_num(value)}"


def summary_lines(record: dict[str, Any]) -> list[str]:
    """The record in a few labelled lines for the terminal, units in each."""
    lines = [f"map       {Path(record['map']['path']).name}, {record['map']['kind']}"]
    noref, grid = record["cloud"], record["grid"]
    if noref is not None:
        near = (f"within {noref['radius_m']:g} m, more than "
                f"{count(noref['min_knn'], 'neighbour')}")
        drawn = noref.get("sampled_points")
        among = "" if drawn is None else f" of {drawn:,} drawn at random"
        lines += [f"points    {noref['points']:,} ({noref['mpv_points']:,}{among} with "
                  f"neighbours {near})",
                  f"MME       {_mean(noref, 'mme', 'nats (lower: crisper)')}",
                  f"MPV       {_mean(noref, 'mpv', 'm² (lower: thinner surfaces)')}",
                  f"MOM       {_num(noref['mom'])}"
                  + (f" ({noref['mom_note']})" if noref["mom"] is None else
                     f" m² (orthogonal planes {noref['orth_subset']})")]
    if grid is not None:
        ratio = grid["occupied_free_ratio"]
        lines += [f"cells     {grid['occupied_cells']:,} occupied of {grid['resolution_m']:g} m"
                  + ("" if grid["free_cells"] is None else f", {grid['free_cells']:,} free"),
                  f"ratio     {_num(ratio)} occupied / free",
                  f"corners   {grid['corners']:,}",
                  "enclosed  " + ("n/a (a cloud has no free cells)"
                                  if grid["enclosed_areas"] is None else
                                  f"{count(grid['enclosed_areas'], 'area')}, "
                                  f"{grid['enclosed_area_m2']:.2f} m²")]
    return lines


def _mean(noref: dict[str, Any], name: str, unit: str) -> str:
    """MME or MPV with its standard error and unit, or ``n/a (why)``."""
    value = noref[name]
    if value is None:
        return f"n/a ({noref.get(f'{name}_note') or 'not finite'})"
    return f"{_num(value)}{_se(noref.get(f'{name}_se'))} {unit}"


def _num(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.6g}"
