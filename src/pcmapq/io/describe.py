"""What pcmapq sees in an input (``pcmapq info``): a recording's topics with their types,
counts and time span (its start on its own clock: time 0 of every command's times); a cloud's
points, bounds and fields; an image's size, resolution, origin, thresholds and the share of its
cells occupied, free and unknown. Metres, degrees, seconds."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from pcmapq.core.bounds import bounds
from pcmapq.core.cells import FREE, OCCUPIED, UNKNOWN
from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.io import load_map
from pcmapq.io.bags import is_bag, opened, span, topics
from pcmapq.io.clouds import PointMap
from pcmapq.io.formats import YAML_SUFFIXES
from pcmapq.io.map_yaml import MapMeta, read_yaml
from pcmapq.io.occupancy import NO_RESOLUTION, OccupancyMap


def describe(path: Path, memory_limit: int | None = None) -> dict[str, Any]:
    """A JSON-ready record of what ``path`` holds for pcmapq; InputError (one line) for a
    file pcmapq cannot read."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: not found")
    if is_bag(path):
        with opened(path) as reader:
            found, times = topics(reader), span(reader)
        start, end = times or (None, None)
        return {"file": str(path), "kind": "recording", "start_s": start, "end_s": end,
                "duration_s": 0.0 if times is None else end - start,
                "topics": [{"name": t.name, "type": t.msgtype, "count": t.count}
                           for t in found]}
    resolution_given = True
    try:
        source = load_map(path, memory_limit=memory_limit)
    except InputError as error:
        if NO_RESOLUTION not in str(error):
            raise
        source, resolution_given = load_map(path, fallback_resolution=1.0,
                                            memory_limit=memory_limit), False
    if isinstance(source, PointMap):
        return _cloud(path, source)
    return _image(path, source, resolution_given)


def lines(record: dict[str, Any]) -> list[str]:
    """The record as the terminal shows it."""
    if record["kind"] == "recording":
        out = [f"{record['file']}: a ROS recording holding no message" if record["start_s"]
               is None else f"{record['file']}: a ROS recording of {record['duration_s']:.1f} "
               f"s, starting at {record['start_s']:.3f} s of its clock (time 0 of --at and "
               "track)"]
        out += [f"  {t['name']}: {t['type']}, {count(t['count'], 'message')}"
                for t in record["topics"]]
        return out
    if "points" in record:
        lo, hi = record["bounds_m"]["min"], record["bounds_m"]["max"]
        fields = f"; fields {', '.join(record['fields'])}" if record["fields"] else ""
        return [f"{record['file']}: {count(record['points'], 'point')} ({record['kind']}, "
                f"{'3D' if record['is_3d'] else '2D'}){fields}",
                "  bounds " + " to ".join("(" + ", ".join(f"{v:.3f}" for v in b) + ") m"
                                          for b in (lo, hi))]
    res = record["resolution_m"]
    cells = record["cells"]
    t = record["thresholds"]
    return [f"{record['file']}: {record['size_px'][0]} x {record['size_px'][1]} px "
            f"({record['kind']}), "
            + (f"{res:g} m per pixel, {record['extent_m'][0]:.2f} x "
               f"{record['extent_m'][1]:.2f} m" if res is not None else
               "no resolution (give one: --map-resolution, --truth-resolution)"),
            f"  origin ({record['origin']['x_m']:g}, {record['origin']['y_m']:g}) m, yaw "
            f"{record['origin']['yaw_deg']:g} deg; occupied_thresh {t['occupied']:g}, "
            f"free_thresh {t['free']:g}, negate {int(t['negate'])}",
            f"  cells: {cells['occupied']:.1%} occupied, {cells['free']:.1%} free, "
            f"{cells['unknown']:.1%} unknown"]


def _cloud(path: Path, source: PointMap) -> dict[str, Any]:
    lo, hi = bounds(source.points)  # column by column: a mapped PLY is not copied
    return {"file": str(path), "kind": source.kind, "points": int(len(source.points)),
            "is_3d": bool(source.is_3d), "fields": _fields(path),
            "bounds_m": {"min": [float(v) for v in lo], "max": [float(v) for v in hi]}}


def _image(path: Path, source: OccupancyMap, resolution_given: bool) -> dict[str, Any]:
    grid, state = source.grid, source.state
    rows, cols = grid.shape
    meta = _meta(path)
    res = grid.resolution if resolution_given else None
    return {"file": str(path), "kind": source.kind, "size_px": [int(cols), int(rows)],
            "resolution_m": res,
            "extent_m": None if res is None else [cols * res, rows * res],
            "origin": {"x_m": grid.origin[0], "y_m": grid.origin[1],
                       "yaw_deg": math.degrees(grid.origin[2])},
            "thresholds": {"occupied": meta.occupied_thresh, "free": meta.free_thresh,
                           "negate": bool(meta.negate)},
            "cells": {name: float(np.count_nonzero(state == value)) / state.size
                      for name, value in (("occupied", OCCUPIED), ("free", FREE),
                                          ("unknown", UNKNOWN))}}


def _meta(path: Path) -> MapMeta:
    """The map_server metadata an image is read with: its YAML's (or the YAML beside it), or
    map_server's defaults."""
    yamls = [path] if path.suffix.lower() in YAML_SUFFIXES else \
        [path.with_suffix(s) for s in YAML_SUFFIXES if path.with_suffix(s).is_file()]
    for candidate in yamls:
        try:
            return read_yaml(candidate)[0]
        except InputError:
            continue
    return MapMeta(resolution=None)


def _fields(path: Path) -> list[str]:
    """The per-point fields a PLY, PCD or LAS file declares (others: none known)."""
    suffix = path.suffix.lower()
    try:
        if suffix == ".pcd":
            from pcmapq.io.pcd import read_header

            return list(read_header(path).fields)
        if suffix == ".ply":
            from pcmapq.io.ply import _header

            _, elements, _ = _header(path)
            return [name for element, _, props in elements if element == "vertex"
                    for name, _ in props]
        if suffix in (".las", ".laz"):
            import laspy

            with laspy.open(path, read_evlrs=False) as reader:
                return list(reader.header.point_format.dimension_names)
    except (InputError, OSError, ValueError):
        return []
    return []
