"""The real 2D maps of the Gazebo, Halmstad and floor-plan cases and their truths as the
no-reference grid figures score them (:func:`pcmapq.metrics.noref2d.grid_scores`): the map at
the pixel size its evaluation estimates (truth cell x scale), the truth at its own."""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

from pcmapq.io import OccupancyMap, Thresholds, load_map
from pcmapq.metrics.noref2d import enclosed_areas, grid_scores

from ..runs import Run
from . import floorplans, gazebo, halmstad


@dataclass(frozen=True)
class Pair:
    """A real map and its truth as a validation section scores them: the evaluation (its
    scale is truth cells per map cell), the map image and its thresholds, the truth image
    (made in a scratch folder) and the truth's cell size, metres."""

    label: str
    case: str
    evaluate: Callable[[], Run]
    map_path: Path
    truth: Callable[[Path], Path]
    truth_resolution: float
    resolution_note: str
    thresholds: Thresholds | None = None


def pairs(data: Path) -> list[Pair]:
    """The Gazebo pair, one Halmstad map per building, and the two floor plans."""
    folder = data / "gazebo"
    out = [Pair("Gazebo", "noref-grid-gazebo", lambda: gazebo.run(data), folder / gazebo.MAP,
                lambda _: folder / gazebo.TRUTH, gazebo.RESOLUTION, "given")]
    for name in halmstad.MAPS:
        map_path, layout = halmstad.paths(data, name)
        out.append(Pair(f"Halmstad {name}", f"noref-grid-{name.lower()}",
                        lambda n=name: halmstad.pipeline(data, n), map_path,
                        lambda tmp, lay=layout: halmstad.halmstad_truth(lay, tmp),
                        halmstad.PLAN_RESOLUTION, "assumed"))
    for plan in floorplans.FLOORPLANS:
        out.append(Pair(plan.name, plan.case.replace("floorplans-", "noref-grid-"),
                        lambda p=plan: floorplans.floorplan_run(p, data),
                        data / "floorplans" / plan.map_file,
                        lambda _, p=plan: data / "floorplans" / p.plan_file,
                        floorplans.PLAN_RESOLUTION, "assumed", plan.thresholds))
    return out


def load_image(path: Path, resolution: float,
               thresholds: Thresholds | None = None) -> OccupancyMap:
    """An occupancy image at ``resolution`` metres per pixel."""
    source = load_map(path, resolution, thresholds=thresholds)
    if not isinstance(source, OccupancyMap):
        raise TypeError(f"{path}: not an image")
    return source


def grid_figures(source: OccupancyMap) -> dict:
    """``grid_scores`` of an image, its cell size (m) and its largest enclosed area (m², 0
    without one: a closed building's interior)."""
    areas = enclosed_areas(source.state, source.grid.resolution)
    return {**asdict(grid_scores(source.state, source.grid)),
            "largest_enclosed_m2": float(areas[0]) if len(areas) else 0.0,
            "resolution_m": source.grid.resolution}


def map_resolution(pair: Pair, run: Run) -> float:
    """The map's pixel size, metres: the truth's cell times the evaluation's scale (the map
    starts at the truth's cell size, so the scale is truth cells per map cell)."""
    return pair.truth_resolution * run.result.transform.scale


@dataclass(frozen=True)
class Scored:
    """One pair: the evaluation against the truth and the grid figures of map and truth."""

    pair: Pair
    run: Run
    map: dict
    truth: dict

    def summary(self) -> dict:
        return {"map": self.map, "truth": self.truth}


def score_pair(pair: Pair) -> Scored:
    """Evaluate a pair, then score its map at the estimated pixel size and its truth."""
    run = pair.evaluate()
    figures = grid_figures(load_image(pair.map_path, map_resolution(pair, run), pair.thresholds))
    with tempfile.TemporaryDirectory(prefix="pcmapq_noref_grids_") as tmp:
        truth = grid_figures(load_image(pair.truth(Path(tmp)), pair.truth_resolution))
    return Scored(pair, run, figures, truth)
