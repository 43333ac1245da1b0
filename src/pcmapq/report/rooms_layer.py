"""The rooms drawn over a panel of the vectorial map (:mod:`pcmapq.report.plot`): the truth's
rooms shaded by status, the map's extra rooms, the rooms' graph through their doors, and their
legend entries. Truth frame, metres."""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.colors import to_rgba
from matplotlib.lines import Line2D

from pcmapq.features.rooms import label_cell
from pcmapq.report.style import EXTRA, MATCHED, MISSING
from pcmapq.results.result import DetectorResult, Result

#: Colours of the rooms' statuses (RGB; drawn translucent over the map).
ROOM_COLOURS = {"matched": MATCHED, "merged": "#e6ab02", "split": "#7570b3",
                "missing": MISSING, "unseen": "#bbbbbb", "extra": EXTRA}


def draw_rooms(ax: Axes, result: Result, det: DetectorResult) -> None:
    """The truth's rooms shaded by status, and the map's extra rooms, on their cells: the
    rooms' grid shares the truth grid's lower-left corner."""
    truth, map_ = det.truth, det.map
    cell = label_cell(truth)
    if not cell:
        return
    rows, cols = truth.labels.shape
    x0, y0 = result.grid.origin[0], result.grid.origin[1]
    colours = np.zeros((len(truth) + 1, 4))
    for k, row in enumerate(result.rooms["truth"]):
        colours[k + 1] = to_rgba(ROOM_COLOURS.get(row["status"], "#bbbbbb"), 0.28)
    overlay = colours[truth.labels]
    extra = [j + 1 for j, row in enumerate(result.rooms["map"]) if row["status"] == "extra"]
    if extra and map_.labels is not None and map_.labels.shape == truth.labels.shape:
        overlay[np.isin(map_.labels, extra)] = to_rgba(ROOM_COLOURS["extra"], 0.45)
    ax.imshow(overlay, extent=(x0, x0 + cols * cell, y0, y0 + rows * cell), origin="upper",
              interpolation="nearest", zorder=2)
    _room_graph(ax, result)


#: Colours of the doors' statuses in the rooms' graph.
DOOR_COLOURS = {"found": "0.35", "not judged": "0.7", "missing": MISSING, "wrong": EXTRA}


def _room_graph(ax: Axes, result: Result) -> None:
    """The rooms' graph over the rooms: each door an edge from one room's centroid through the
    door to the other's, grey when found (light: not judged), red when the map misses it;
    the map's wrong doors (joining rooms the truth does not) orange, through the map's rooms."""
    for side, statuses in (("truth", ("found", "not judged", "missing")), ("map", ("wrong",))):
        rooms, doors = result.rooms[side], result.rooms["doors"][side]
        for status in statuses:
            paths = [[(rooms[a]["x_m"], rooms[a]["y_m"]), (d["x_m"], d["y_m"]),
                      (rooms[b]["x_m"], rooms[b]["y_m"])]
                     for d in doors if d["status"] == status for a, b in [d["rooms"]]]
            if paths:
                ax.add_collection(LineCollection(
                    paths, colors=DOOR_COLOURS[status], zorder=2.5,
                    linewidths=0.8 if status in ("found", "not judged") else 1.4,
                    linestyles="solid" if status in ("found", "not judged") else "dashed"))


def rooms_legend(rooms: dict) -> list[Line2D]:
    """Legend entries of the rooms (``Result.rooms``): each room status shown, the doors the map
    misses or has wrong, and the truth's doors when there are any."""
    shown = {row["status"] for side in ("truth", "map") for row in rooms[side]}
    handles = [Line2D([], [], color=colour, lw=6, alpha=0.45, label=f"room {status}")
               for status, colour in ROOM_COLOURS.items() if status in shown]
    doors = rooms.get("doors", {})
    drawn = {d["status"] for side in ("truth", "map") for d in doors.get(side, [])} - {"found"}
    handles += [Line2D([], [], color=DOOR_COLOURS[status], lw=1.4, ls="--",
                       label=f"door {status}") for status in ("missing", "wrong")
                if status in drawn]
    if doors.get("truth"):
        handles.append(Line2D([], [], color=DOOR_COLOURS["found"], lw=0.8,
                              label="rooms joined by a door (truth)"))
    return handles
