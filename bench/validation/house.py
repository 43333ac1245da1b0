"""Real robot maps with free space against real plans and reference maps: the right pose and
the verdict, by the evidence of the maps' free space (docs/method.md, "Another place").

The maps are ROS maps of three buildings (../shared/data/plans): a house's architectural plan
and two Cartographer maps of it (``gopi5go_house``), an office floor's furniture-free reference
map and two robot maps of it (``bonn_youbot_tmcl``), and a real robot map of an office against
the map of its simulation model (``strands_g4s``). Every map is scored against its own
building's truth (same place) and against the other buildings' truths (another place), with
``force`` and no detectors, as ``pcmapq eval`` places it by default.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.evaluation.same_place import SEEN_THROUGH
from pcmapq.io import load_map
from pcmapq.raster.draw import OCCUPIED
from pcmapq.results.result import LOW, OTHER
from pcmapq.settings import AlignmentConfig, MatchingConfig, Settings
from testkit import reference

from .common import Case, Record, Section, header, row

SETTINGS = Settings(alignment=AlignmentConfig(force=True), matching=MatchingConfig(detectors=()))
#: Each map: its building, the path under plans/, and the reference placement on its own
#: building's truth (x m, y m, yaw deg) where one is known (the house's README; the Bonn robot
#: map is drawn in its reference map's frame).
MAPS = {
    "house_tile_cart": ("house", "gopi5go_house/house_tile_cart.yaml", (0.405, -0.433, 1.63)),
    "cart_office": ("house", "gopi5go_house/cart_office.yaml", (0.371, -0.922, 2.55)),
    "GMap": ("bonn", "bonn_youbot_tmcl/GMap/GMap.yaml", (0.0, 0.0, 0.0)),
    "YouBotMap": ("bonn", "bonn_youbot_tmcl/2021_10_27/YouBotMap.yaml", None),
    "g4s_y2": ("g4s", "strands_g4s/g4s_y2.yaml", None),
}
TRUTHS = {"house": "gopi5go_house/floorplan.map.yaml", "bonn": "bonn_youbot_tmcl/Faro/FMap.yaml",
          "g4s": "strands_g4s/g4s_sim_cropped.yaml"}


@dataclass(frozen=True)
class Placed:
    """One pair's figures (its reference keeps them) and whether the map shows the place."""

    map_name: str
    truth_name: str
    same: bool
    figures: dict
    error: tuple[float, float] | None

    def summary(self) -> dict:
        return self.figures


def pairs() -> list[tuple[str, str, bool]]:
    """(map, truth building, same place) of every map against every building's truth."""
    return [(name, building, building == own)
            for name, (own, _, _) in MAPS.items() for building in TRUTHS]


def measure(data: Path, name: str, building: str) -> Placed:
    """One map scored against one building's truth."""
    own, path, ref = MAPS[name]
    result = evaluate(data / "plans" / path, data / "plans" / TRUTHS[building], SETTINGS)
    doc = result.to_dict()
    figures = reference.summary(doc)
    figures["alignment"].update({k: doc["alignment"][k] for k in
                                 ("verdict", "seen_through", "contradiction", "free_on_truth")})
    error = None
    if ref is not None and own == building:
        tf = result.transform
        error = (float(np.hypot(tf.tx - ref[0], tf.ty - ref[1])),
                 abs((tf.yaw_deg - ref[2] + 180.0) % 360.0 - 180.0))
    return Placed(name, building, own == building, figures, error)


@dataclass(frozen=True)
class Chained:
    """cart_office placed on the plan through house_tile_cart: its pose on that map (fitness,
    confidence), composed with house_tile_cart's reference placement on the plan, and how far
    that puts it from cart_office's own reference and from where the plan alone places it
    (metres at the map's centre, degrees)."""

    pose: tuple[float, float, float]
    fitness: float
    confidence: float
    from_reference: tuple[float, float]
    from_plan: tuple[float, float]

    def summary(self) -> dict:
        return {"pose": [round(v, 6) for v in self.pose], "fitness": round(self.fitness, 6),
                "confidence": round(self.confidence, 6),
                "from_reference": [round(v, 6) for v in self.from_reference],
                "from_plan": [round(v, 6) for v in self.from_plan]}


def _apart(a: Similarity2D, b: Similarity2D, at: np.ndarray) -> tuple[float, float]:
    """How far two poses put the point ``at`` (map frame) apart, metres, and their turn, deg."""
    return (float(np.linalg.norm(a.apply(at) - b.apply(at))),
            abs((a.yaw_deg - b.yaw_deg + 180.0) % 360.0 - 180.0))


def chained(data: Path) -> Chained:
    """cart_office on house_tile_cart, then on the plan by house_tile_cart's reference."""
    folder = data / "plans"
    office, house, plan = (folder / MAPS["cart_office"][1], folder / MAPS["house_tile_cart"][1],
                           folder / TRUTHS["house"])
    on_house = evaluate(office, house, SETTINGS)
    on_plan = evaluate(office, plan, SETTINGS)
    pose = _pose(MAPS["house_tile_cart"][2]).compose(on_house.transform)
    centre = _centre(office).reshape(1, 2)
    return Chained((pose.tx, pose.ty, pose.yaw_deg), on_house.alignment.fitness,
                   on_house.overlap.confidence,
                   _apart(pose, _pose(MAPS["cart_office"][2]), centre),
                   _apart(pose, on_plan.transform, centre))


def _pose(xyd: tuple[float, float, float]) -> Similarity2D:
    return Similarity2D(xyd[0], xyd[1], math.radians(xyd[2]))


def _centre(path: Path) -> np.ndarray:
    """The centre of a ROS map's occupied cells, metres, its own frame."""
    source = load_map(path)
    return source.grid.cell_centres(source.state == OCCUPIED).mean(axis=0)


def cases(data: Path) -> list[Case]:
    return [*(Case(f"house-{name}-{building}", lambda n=name, b=building: measure(data, n, b))
              for name, building, _ in pairs()),
            Case("house-cart_office-through-house_tile_cart", lambda: chained(data))]


def _cell(value: float | None, digits: int = 2) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def section(data: Path, record: Record) -> Section:
    """The table of every pair, and what the verdict made of them."""
    *placed, chain = [case.run(record) for case in cases(data)]
    lines = [header(["map", "truth", "place", "verdict", "pose error", "seen through",
                     "contradiction", "free on truth", "truth recall", "fitness",
                     "distinctiveness", "confidence"])]
    for p in placed:
        a = p.figures["alignment"]
        wrong = (a["verdict"] == OTHER) == p.same
        lines.append(row([
            p.map_name, p.truth_name, "same" if p.same else "other",
            f"**{a['verdict']}**" if wrong else a["verdict"],
            "-" if p.error is None else f"{p.error[0]:.2f} m, {p.error[1]:.1f} deg",
            _cell(a["seen_through"], 3), _cell(a["contradiction"], 3),
            _cell(a["free_on_truth"]), _cell(a["truth_recall"]),
            _cell(a["fitness"]), _cell(a["distinctiveness"]), _cell(a["confidence"])]))
    same = [p for p in placed if p.same]
    other = [p for p in placed if not p.same]
    refused = sum(p.figures["alignment"]["verdict"] == OTHER for p in other)
    scored = sum(p.figures["alignment"]["verdict"] != OTHER for p in same)
    low = [p for p in placed if p.figures["alignment"]["verdict"] == LOW]

    def through(group: list[Placed]) -> list[float]:
        return [p.figures["alignment"]["seen_through"] for p in group]

    return Section("\n".join([
        "## Maps with free space: real robot maps against real plans", "",
        "Five ROS maps of three buildings (`../shared/data/plans`): the Cartographer maps of a "
        "house (`gopi5go_house`: most of the house, and one cluttered office) against the "
        "house's architectural plan (cabinets drawn as solid blocks), two robot maps of an "
        "office floor (`bonn_youbot_tmcl`) against its furniture-free reference map, and a "
        "robot map of an office (`strands_g4s`) against the map of its simulation model; each "
        "against its own building's truth and the two others', with `force` and no detectors "
        "(`python -m bench.validation --only house`). The house's maps are saved by Nav2's "
        "map_saver with `free_thresh: 0.25`, read with their grey 205 unknown "
        "(docs/formats.md). \"pose error\": from the reference placement, where one is "
        "known (the house's README; the Bonn robot map shares its reference map's frame); "
        "\"seen through\": the share of the truth's walls the map covers that lie on its free "
        "space (walls it saw through; the verdict's evidence of another place from "
        f"{SEEN_THROUGH} on); \"contradiction\": the share of the map's free cells on the "
        "truth's known cells that lie on its walls; \"free on truth\": the share of the "
        "map's free cells on the truth's known cells (docs/metrics.md). A wrong verdict is in "
        "bold.", "",
        *lines, "",
        f"The verdict scores {scored} of the {len(same)} same-place pairs and refuses "
        f"{refused} of the {len(other)} other-place pairs. Same place, the maps saw through "
        f"{min(through(same)):.3f}-{max(through(same)):.3f} of the truth's walls; other "
        f"places {min(through(other)):.3f}-{max(through(other)):.3f}. "
        + ("Placed with low confidence: "
           + ", ".join(f"{p.map_name} on {p.truth_name}" for p in low)
           + ": the one-room office map fits a room of other offices as it fits the hall of "
           "its own house, seeing through few walls at each; nothing it holds tells them "
           "apart, and the verdict flags it rather than guess." if low else ""),
        "",
        "cart_office's reference placement (its README's, found by ICP from a hand guess "
        "against the plan) is not the pose its own house's other map gives it. Placed on "
        f"house_tile_cart (fitness {chain.fitness:.2f}, confidence {chain.confidence:.2f}) "
        "and carried to the plan by house_tile_cart's reference, it lands at "
        f"({chain.pose[0]:.2f} m, {chain.pose[1]:.2f} m, {chain.pose[2]:.1f} deg): "
        f"{chain.from_reference[0]:.2f} m and {chain.from_reference[1]:.1f} deg from its "
        f"reference, {chain.from_plan[0]:.2f} m and {chain.from_plan[1]:.1f} deg from where the "
        "plan alone places it.",
    ]))
