"""The option table: every setting a user can give, once. Each :class:`Option` names the
command-line option, its kind and bounds, its help, the commands that take it and its path in
:class:`~pcmapq.settings.Settings`. The typer commands, the batch manifest's columns, the
settings builder (:mod:`pcmapq.settings.build`) and the settings file
(:mod:`pcmapq.settings.file`) all read it: an option added here reaches every one of them."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.raster.rules import FOOTPRINT_RULES
from pcmapq.settings import DETECTOR_NAMES

#: Kinds of option: a number, an integer, text read by the option's parser, or a switch
#: (``--noref/--no-noref``: a yes or no the command line can give either way).
FLOAT, INT, TEXT, SWITCH = "float", "int", "text", "switch"
#: The commands that take settings.
EVAL, BATCH, TRACK, INSPECT = "eval", "batch", "track", "inspect"


class OptionError(InputError):
    """An option's value that cannot be read: one line, naming the option (exit 2)."""

    def __init__(self, message: str, option: str) -> None:
        super().__init__(message)
        self.message, self.option = message, option


def _same(value: Any) -> Any:
    return value


@dataclass(frozen=True)
class Option:
    """One setting as a user gives it.

    name: the parameter and manifest column (``map_resolution``); ``flag``: the option as
    typed when not ``--map-resolution`` (a switch's ``--x/--no-x``). path: where it goes in
    :class:`Settings` (dotted). kind, lo, hi: its type and bounds. read: its value (text for a
    TEXT option) -> the setting, OptionError when unreadable; show: the setting -> the
    option's value (the default shown, a settings file checked). also: other settings its
    value sets. commands: the commands that take it; helps: a command's own help."""

    name: str
    path: str
    kind: str
    help: str
    lo: float = -math.inf
    hi: float = math.inf
    flag: str | None = None
    metavar: str | None = None
    read: Callable[[Any], Any] = _same
    show: Callable[[Any], Any] = _same
    also: Callable[[Any], dict[str, Any]] = lambda value: {}
    commands: tuple[str, ...] = (EVAL, BATCH)
    helps: dict[str, str] = field(default_factory=dict)

    @property
    def option(self) -> str:
        """The option as typed: ``--map-resolution``."""
        return (self.flag or "--" + self.name.replace("_", "-")).split("/")[0]

    @property
    def bounds(self) -> str:
        """The option's bounds as a refusal says them: `` >= 0.01``, `` in [0, 1]``, or ''."""
        if self.lo == -math.inf:
            return ""
        return f" >= {self.lo:g}" if self.hi == math.inf else f" in [{self.lo:g}, {self.hi:g}]"

    def help_for(self, command: str) -> str:
        return self.helps.get(command, self.help)


def parse_init(text: str) -> Similarity2D:
    """``x,y,yaw`` (metres, metres, degrees; finite) as a map -> truth guess."""
    try:
        x, y, yaw = (float(v) for v in text.split(","))
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(text)
    except ValueError:
        raise OptionError(f"expected finite x,y,yaw (metres, metres, degrees), got {text!r}",
                          "--init") from None
    return Similarity2D(x, y, float(np.radians(yaw)))


def show_init(tf: Similarity2D | None) -> str | None:
    return None if tf is None else f"{tf.tx:g},{tf.ty:g},{np.degrees(tf.yaw):g}"


def parse_box(text: str, option: str) -> tuple[float, float, float, float]:
    """A box ``x0,y0,x1,y1`` (metres, finite, x0 < x1, y0 < y1)."""
    try:
        x0, y0, x1, y1 = (float(v) for v in text.split(","))
        if not (all(math.isfinite(v) for v in (x0, y0, x1, y1)) and x0 < x1 and y0 < y1):
            raise ValueError(text)
    except ValueError:
        raise OptionError(f"expected a box x0,y0,x1,y1 in metres with x0 < x1 and y0 < y1, got "
                          f"{text!r}", option) from None
    return x0, y0, x1, y1


def show_list(values: tuple | None) -> str | None:
    return None if values is None else ",".join(f"{v:g}" if isinstance(v, float) else str(v)
                                                for v in values)


def parse_map_resolution(text: str) -> float | None:
    """Metres per pixel, or ``auto`` (None: the scale is estimated)."""
    if text == "auto":
        return None
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 < value < math.inf:
        raise OptionError(f"expected metres per pixel or 'auto', got {text!r}",
                          "--map-resolution")
    return value


def parse_scale(text: str) -> bool:
    if text not in ("fixed", "auto"):
        raise OptionError(f"expected 'fixed' or 'auto', got {text!r}", "--scale")
    return text == "auto"


def parse_taus(text: str) -> tuple[float, ...]:
    """Positive finite distances, metres, comma-separated."""
    try:
        taus = tuple(float(v) for v in text.split(","))
    except ValueError:
        taus = ()
    if not taus or not all(0 < t < math.inf for t in taus):
        raise OptionError(f"expected positive finite distances in metres, got {text!r}",
                          "--tau")
    return taus


def parse_detectors(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    unknown = [n for n in names if n not in DETECTOR_NAMES]
    if unknown or not names:
        raise OptionError(f"unknown detector(s) {unknown}; choose from "
                          f"{','.join(DETECTOR_NAMES)}", "--detectors")
    return names


def parse_footprint(text: str) -> str:
    if text not in FOOTPRINT_RULES:
        raise OptionError(f"expected one of {', '.join(FOOTPRINT_RULES)}, got {text!r}",
                          "--footprint")
    return text


def _thresholds(side: str) -> list[Option]:
    """map_server's reading options of one side's image."""
    other = "as --map-" if side == "truth" else None
    return [
        Option(f"{side}_occupied_thresh", f"{side}.thresholds.occupied", FLOAT,
               f"Truth image: {other}occupied-thresh." if other else
               "Map image: occupied if p > this (map_server's occupied_thresh; overrides the "
               "YAML's, default 0.65).", 0.0, 1.0),
        Option(f"{side}_free_thresh", f"{side}.thresholds.free", FLOAT,
               f"Truth image: {other}free-thresh." if other else
               "Map image: free if p < this (map_server's free_thresh; overrides the YAML's, "
               "default 0.196).", 0.0, 1.0),
        Option(f"{side}_negate", f"{side}.thresholds.negate", SWITCH,
               f"Truth image: {other}negate." if other else
               "Map image: p = v / 255 instead of (255 - v) / 255 (map_server's negate; "
               "overrides the YAML's).", flag=f"--{side}-negate/--{side}-no-negate"),
    ]


#: Every option, in the order the commands list them.
OPTIONS: tuple[Option, ...] = (
    Option("scale", "alignment.scale", TEXT,
           "'fixed': the map's metres are metres; 'auto': estimate its scale too (a "
           "similarity), for maps whose resolution is unknown.", metavar="<fixed|auto>",
           read=parse_scale, show=lambda auto: "auto" if auto else "fixed"),
    Option("map_resolution", "map.resolution", TEXT,
           "Metres per pixel of a map image without YAML (overrides its YAML); 'auto' "
           "estimates the map's scale (same as --scale auto).", metavar="<metres|auto>",
           read=parse_map_resolution, show=lambda r: None if r is None else f"{r:g}",
           also=lambda r: {"alignment.scale": True} if r is None else {}),
    Option("map_resolution", "map.resolution", FLOAT,
           "Metres per pixel of an image without YAML.", 1e-6, commands=(INSPECT,)),
    Option("truth_resolution", "truth.resolution", FLOAT,
           "Metres per pixel of a truth image without YAML; cell size for a cloud truth "
           "(default 0.05).", 1e-6, commands=(EVAL, BATCH, TRACK), helps={TRACK: "As eval's."}),
    *_thresholds("map"), *_thresholds("truth"),
    Option("map_crop", "map.crop", TEXT,
           "Keep only the map's part inside this box, metres, in its own frame (outlier "
           "points far away).", metavar="<x0,y0,x1,y1>",
           read=lambda t: parse_box(t, "--map-crop"), show=show_list),
    Option("crop", "map.crop", TEXT,
           "Keep only the part of the map inside this box, metres, in its own frame (as "
           "eval's --map-crop).", metavar="<x0,y0,x1,y1>",
           read=lambda t: parse_box(t, "--crop"), show=show_list, commands=(INSPECT,)),
    Option("map_topic", "map.topic", TEXT,
           "A ROS recording map: its OccupancyGrid topic (default: the only one, or /map).",
           metavar="<topic>"),
    Option("at", "map.at", FLOAT,
           "A ROS recording map: the map recorded at this time, seconds from the recording's "
           "start (its first message; the last map at or before it; default: the last)."),
    Option("truth_topic", "truth.topic", TEXT,
           "A ROS recording truth: its OccupancyGrid topic (default: the only one, or /map).",
           metavar="<topic>"),
    Option("topic", "map.topic", TEXT,
           "A ROS recording map: its OccupancyGrid topic (default: the only one, or /map).",
           metavar="<topic>", commands=(INSPECT,)),
    Option("truth_crop", "truth.crop", TEXT,
           "Keep only the truth's part inside this box, metres, in its own frame.",
           metavar="<x0,y0,x1,y1>", read=lambda t: parse_box(t, "--truth-crop"),
           show=show_list),
    Option("init", "alignment.init", TEXT,
           "Initial guess x,y,yaw (m, m, deg), map -> truth; skips the global search (ICP "
           "still refines).", metavar="<x,y,yaw>",
           read=parse_init, show=show_init, commands=(EVAL, BATCH, TRACK),
           helps={TRACK: "Initial guess x,y,yaw (m, m, deg), map -> truth, of the first "
                         "step; skips the global search."}),
    Option("no_align", "alignment.enabled", SWITCH, "Trust the map's frame: no alignment at all.",
           flag="--no-align/--align", read=lambda off: not off, show=lambda on: not on,
           commands=(EVAL, BATCH, TRACK),
           helps={TRACK: "Trust the run's frame: no alignment at any step."}),
    Option("force", "alignment.force", SWITCH,
           "Evaluate even when the map does not seem to show the truth's place.",
           flag="--force/--no-force", commands=(EVAL, BATCH, TRACK),
           helps={TRACK: "Score every step, even one that does not seem to show the truth's "
                         "place."}),
    Option("threshold", "matching.threshold", FLOAT,
           "Largest distance between matched features, metres.", 1e-6,
           commands=(EVAL, BATCH, TRACK)),
    Option("band_low", "raster.band_low", FLOAT,
           "Wall band of a 3D cloud: lower bound, metres above the floor."),
    Option("band_high", "raster.band_high", FLOAT,
           "Wall band of a 3D cloud: upper bound, metres above the floor."),
    Option("min_hits", "raster.min_hits", INT,
           "Points needed to mark a cloud's cell occupied (default: 2 for a 3D cloud, 1 for a "
           "2D one).", 1),
    Option("detectors", "matching.detectors", TEXT,
           f"Comma-separated detectors to run, any of {', '.join(DETECTOR_NAMES)}.",
           metavar="<" + ",".join(DETECTOR_NAMES) + ">", read=parse_detectors, show=show_list,
           commands=(EVAL, BATCH, TRACK), helps={TRACK: "As eval's."}),
    Option("voxel_3d", "alignment.voxel_3d", FLOAT,
           "Working voxel of the 3D registration of two 3D clouds, metres (0.5-1 for outdoor "
           "maps).", 0.01, flag="--voxel-3d"),
    Option("tau", "distances.taus", TEXT,
           "Distance thresholds of the F-score, metres, comma-separated.", metavar="<M,M,...>",
           read=parse_taus, show=show_list, commands=(EVAL, BATCH, TRACK),
           helps={TRACK: "Distance thresholds of the F-score and wall precision, metres."}),
    Option("footprint", "footprint.rule", TEXT,
           "The area the map observed: 'known' cells of an image, the area its 'walls' "
           "enclose, 'all' of its rectangle; 'auto': known cells for an image with unknown "
           "regions, walls for a binary image or a cloud.",
           metavar="<" + "|".join(r for r in FOOTPRINT_RULES if r != "seen") + ">",
           read=parse_footprint, commands=(EVAL, BATCH, TRACK),
           helps={TRACK: "As eval's; 'auto' is 'seen': the area the scans so far saw."}),
    Option("margin", "footprint.margin", FLOAT,
           "The map's footprint is grown by this much, metres: truth features that far "
           "outside the area the map observed still count as missing.", 0.0,
           commands=(EVAL, BATCH, TRACK)),
    Option("full", "footprint.full", SWITCH,
           "Score against the whole truth, not only the part the map covers.",
           flag="--full/--no-full"),
    Option("noref", "noref.enabled", SWITCH,
           "Also report each input's no-reference figures, as 'pcmapq inspect' does (MME, "
           "MPV, MOM of a 3D cloud; occupancy figures of a 2D map).", flag="--noref/--no-noref"),
    Option("noref_radius", "noref.radius", FLOAT,
           "Neighbourhood of the 3D no-reference figures, metres (0.2 for depth-camera maps, "
           "with --noref-voxel 0.02).", 1e-6),
    Option("noref_voxel", "noref.voxel", FLOAT,
           "A 3D cloud is first reduced to one point per cell of this size for its "
           "no-reference figures, metres (0: as it is).", 0.0),
    Option("noref_sample", "noref.sample", INT,
           "MME and MPV of a 3D cloud are means over this many of its points drawn at random "
           "(seeded), their standard errors reported, and MOM's planes are found on the cloud "
           "at a third of the radius (0: every point, as 'pcmapq inspect').", 0),
    Option("radius", "noref.radius", FLOAT,
           "Neighbourhood radius of MME, MPV and MOM, metres (1 for LiDAR maps, 0.2 for depth "
           "cameras).", 1e-6, commands=(INSPECT,)),
    Option("min_knn", "noref.min_knn", INT,
           "A point counts when it has more than this many neighbours.", 0,
           commands=(INSPECT,)),
    Option("max_nn", "noref.max_nn", INT,
           "Nearest neighbours of the normals that pick MOM's orthogonal planes.", 3,
           commands=(INSPECT,)),
    Option("voxel", "noref.voxel", FLOAT,
           "First reduce a 3D cloud to one point (the centroid) per cell of this size, "
           "metres; 0: as it is, as map-metrics ('pcmapq eval' uses 0.1).", 0.0,
           commands=(INSPECT,)),
    Option("sample", "noref.sample", INT,
           "MME and MPV over this many points drawn at random (seeded), with their standard "
           "errors, and MOM's planes from the cloud at a third of the radius; 0: every point, "
           "as map-metrics ('pcmapq eval' uses 20000).", 0, commands=(INSPECT,)),
    Option("structures", "structures.enabled", SWITCH,
           "Two 3D clouds: also find their planes and the lines where two planes meet, and "
           "match them one to one (quality, precision, f1, displacements).",
           flag="--structures/--no-structures"),
    Option("structures_voxel", "structures.voxel", FLOAT,
           "3D structures: each cloud is reduced to one point per voxel of this side before "
           "its planes are found, metres (0.3 for outdoor LiDAR maps).", 0.01),
    Option("plane_min_points", "structures.min_points", INT,
           "3D structures: the fewest reduced points of a plane.", 3),
    Option("plane_min_area", "structures.min_area", FLOAT,
           "3D structures: the least area of a plane, square metres.", 0.0),
    Option("structures_angle", "structures.max_angle", FLOAT,
           "3D structures: the largest angle between matched planes or lines, degrees.",
           0.0, 90.0),
    Option("structures_offset", "structures.max_offset", FLOAT,
           "3D structures: the largest distance between matched planes (along the truth "
           "plane's normal) or lines, metres.", 1e-6),
    Option("line_margin", "structures.line_margin", FLOAT,
           "3D structures: two planes meet in a line where their extents touch within this, "
           "metres.", 0.0),
)


def options_of(command: str) -> tuple[Option, ...]:
    """The options ``command`` takes, in table order."""
    return tuple(o for o in OPTIONS if command in o.commands)
