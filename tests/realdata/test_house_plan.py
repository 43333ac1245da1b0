"""Real home-robot maps against their house's architectural plan (../shared/data/plans/
gopi5go_house: Cartographer maps saved by Nav2's map_saver with free_thresh 0.25, a plan with
cabinets drawn as solid blocks), and against another building's reference map."""

from __future__ import annotations

import json

import numpy as np

from testkit.command import run_process as run
from testkit.paths import shared

HOUSE = ("plans", "gopi5go_house")
#: The README's reference placements (map -> plan: x m, y m, yaw deg), found by hand.
REFERENCE = {"house_tile_cart": (0.405, -0.433, 1.63), "cart_office": (0.371, -0.922, 2.55)}


def _eval(map_path, truth_path) -> tuple[int, dict | None, str]:
    proc = run("eval", str(map_path), str(truth_path), "--no-noref", "--detectors", "harris",
               "--json", "-")
    return proc.returncode, json.loads(proc.stdout) if proc.returncode == 0 else None, \
        proc.stderr


def test_house_map_placed_at_its_reference():
    """Most of the house: within 0.3 m and 2 degrees of the reference, same place, its free
    space on the plan's walls almost nowhere (measured 0.35, -0.46, 1.70 deg; contradiction
    0.013)."""
    code, doc, err = _eval(shared(*HOUSE, "house_tile_cart.yaml"),
                           shared(*HOUSE, "floorplan.map.yaml"))
    assert code == 0, err
    a = doc["alignment"]
    x, y, yaw = REFERENCE["house_tile_cart"]
    assert np.hypot(a["x_m"] - x, a["y_m"] - y) < 0.3 and abs(a["yaw_deg"] - yaw) < 2.0
    assert a["verdict"] == "same place" and a["contradiction"] < 0.05
    assert "map_saver's unknown grey 205" in err


def test_one_room_map_scored_with_low_confidence():
    """One cluttered office: its room fits the hall as well as the office (fitness 0.48 and
    0.43), so no pose stands out; it saw through few of the plan's walls there (0.03), so it
    is scored, flagged with the search's two best poses, not refused as another place."""
    code, doc, err = _eval(shared(*HOUSE, "cart_office.yaml"),
                           shared(*HOUSE, "floorplan.map.yaml"))
    assert code == 0, err
    a = doc["alignment"]
    assert a["verdict"] == "placed with low confidence"
    assert a["seen_through"] < 0.1 and a["truth_recall"] > 0.4
    assert len(a["poses"]) == 2 and all("score" in p for p in a["poses"])


def test_house_map_against_another_building_is_refused():
    """The house against Bonn's office floor: where its walls fit best, its free space covers
    0.22 of that floor's walls it spans: another place, the one line says so."""
    code, _, err = _eval(shared(*HOUSE, "house_tile_cart.yaml"),
                         shared("plans", "bonn_youbot_tmcl", "Faro", "FMap.yaml"))
    assert code == 1 and "another place" in err and "saw through" in err, err
