"""The option table: every setting a user can give, once. Each :class:`Option` names the
command-line option, its kind and bounds, its help, the commands that take it and its path in
:class:`~pcmapq.settings.Settings`. The typer commands, the batch manifest's columns, the
settings builder (:mod:`pcmapq.settings.build`) and the settings file
(:mod:`pcmapq.settings.file`) and the docs' option tables (:mod:`pcmapq.report.docs_tables`)
all read it: an option added here reaches every one of them. An option has one name on every
command; :mod:`pcmapq.settings.renamed` lists the former names still read, with a
warning."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from pcmapq.features.names import DETECTOR_NAMES
from pcmapq.io.map_yaml import MapMeta
from pcmapq.raster.rules import FOOTPRINT_RULES
from pcmapq.settings.configs import (
    EVAL_NOREF_SAMPLE,
    EVAL_NOREF_VOXEL,
    MIN_HITS_2D,
    MIN_HITS_3D,
    RasterConfig,
)
from pcmapq.settings.parsers import (
    OptionError,
    parse_box,
    parse_detectors,
    parse_footprint,
    parse_init,
    parse_init_3d,
    parse_map_resolution,
    parse_scale,
    parse_taus,
    show_init,
    show_init_3d,
    show_list,
)

__all__ = ["BATCH", "EVAL", "FLOAT", "INSPECT", "INT", "OPTIONS", "SWITCH", "TEXT", "TRACK",
           "Option", "OptionError", "option_named", "options_of", "parse_box"]

#: Kinds of option: a number, an integer, text read by the option's parser, or a switch
#: (``--noref/--no-noref``: a yes or no the command line can give either way).
FLOAT, INT, TEXT, SWITCH = "float", "int", "text", "switch"
#: The commands that take settings.
EVAL, BATCH, TRACK, INSPECT = "eval", "batch", "track", "inspect"


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


def _thresholds(side: str) -> list[Option]:
    """map_server's reading options of one side's image."""
    other = "as --map-" if side == "truth" else None
    return [
        Option(f"{side}_occupied_thresh", f"{side}.thresholds.occupied", FLOAT,
               f"Truth image: {other}occupied-thresh." if other else
               "Map image: occupied if p > this (map_server's occupied_thresh; overrides the "
               f"YAML's, default {MapMeta.occupied_thresh:g}).", 0.0, 1.0),
        Option(f"{side}_free_thresh", f"{side}.thresholds.free", FLOAT,
               f"Truth image: {other}free-thresh." if other else
               "Map image: free if p < this (map_server's free_thresh; overrides the YAML's, "
               f"default {MapMeta.free_thresh:g}).", 0.0, 1.0),
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
           also=lambda r: {"alignment.scale": True} if r is None else {},
           commands=(EVAL, BATCH, INSPECT),
           helps={INSPECT: "Metres per pixel of an image without YAML (overrides its "
                           "YAML)."}),
    Option("truth_resolution", "truth.resolution", FLOAT,
           "Metres per pixel of a truth image without YAML; cell size for a cloud truth "
           f"(default {RasterConfig.cloud_resolution:g}).", 1e-6, commands=(EVAL, BATCH, TRACK),
           helps={TRACK: "As eval's."}),
    *_thresholds("map"), *_thresholds("truth"),
    Option("map_crop", "map.crop", TEXT,
           "Keep only the map's part inside this box, metres, in its own frame (outlier "
           "points far away).", metavar="<x0,y0,x1,y1>",
           read=lambda t: parse_box(t, "--map-crop"), show=show_list,
           commands=(EVAL, BATCH, INSPECT)),
    Option("map_topic", "map.topic", TEXT,
           "A ROS recording map: its OccupancyGrid topic (default: the only one, or /map).",
           metavar="<topic>", commands=(EVAL, BATCH, INSPECT)),
    Option("at", "map.at", FLOAT,
           "A ROS recording map: the map recorded at this time, seconds from the recording's "
           "start (its first message; the last map at or before it; default: the last)."),
    Option("truth_topic", "truth.topic", TEXT,
           "A ROS recording truth: its OccupancyGrid topic (default: the only one, or /map).",
           metavar="<topic>"),
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
    Option("init_3d", "alignment.init_3d", TEXT,
           "Two 3D clouds: start the 3D registration from this rigid map -> truth transform "
           "('identity' for clouds in one frame, 16 comma-separated numbers row by row, or a "
           "file of its 4x4 matrix as --transform writes it); skips the global search (ICP "
           "still refines).", metavar="<identity|matrix|path>",
           read=parse_init_3d, show=show_init_3d, commands=(EVAL, BATCH)),
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
           f"Points needed to mark a cloud's cell occupied (default: {MIN_HITS_3D} for a 3D "
           f"cloud, {MIN_HITS_2D} for a 2D one).", 1),
    Option("detectors", "matching.detectors", TEXT,
           f"Comma-separated detectors to run, any of {', '.join(DETECTOR_NAMES)}.",
           metavar="<" + ",".join(DETECTOR_NAMES) + ">", read=parse_detectors, show=show_list,
           commands=(EVAL, BATCH, TRACK), helps={TRACK: "As eval's."}),
    Option("voxel_3d", "alignment.voxel_3d", FLOAT,
           "Working voxel of the 3D registration of two 3D clouds, metres (0.5-1 for outdoor "
           "maps).", 0.01, flag="--voxel-3d"),
    Option("awd_voxel", "map_3d.voxel", FLOAT,
           "Two 3D clouds: side of the voxels of AWD and SCS, metres (MapEval's 3; 2-4 "
           "outdoors, 2-3 indoors).", 0.01),
    Option("awd_min_points", "map_3d.min_points", INT,
           "Two 3D clouds: points a voxel needs in each cloud to count in AWD and SCS.", 2),
    Option("scs_radius", "map_3d.radius", INT,
           "Two 3D clouds: SCS compares a voxel's neighbours within this many voxels along "
           "each axis.", 1),
    Option("tile_3d", "map_3d.tile", FLOAT,
           "Side of the tiles of the 3D consistency map of two 3D clouds (each tile of the map "
           "registered to the truth on its own), metres.", 1.0, flag="--tile-3d"),
    Option("stretch_3d", "map_3d.stretch", INT,
           "A 3D map that carries its points' scans ('pcmapq map' writes them): scans per "
           "stretch of the run, the regions of its 3D consistency map (default: at least 4, "
           "at most 32 stretches); 0: tiles of --tile-3d instead.", 0, flag="--stretch-3d"),
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
           "with --noref-voxel 0.02).", 1e-6, commands=(EVAL, BATCH, INSPECT),
           helps={INSPECT: "Neighbourhood radius of MME, MPV and MOM, metres (1 for LiDAR "
                           "maps, 0.2 for depth cameras)."}),
    Option("noref_voxel", "noref.voxel", FLOAT,
           "A 3D cloud is first reduced to one point per cell of this size for its "
           "no-reference figures, metres (0: as it is).", 0.0, commands=(EVAL, BATCH, INSPECT),
           helps={INSPECT: "First reduce a 3D cloud to one point (the centroid) per cell of "
                           "this size, metres; 0: as it is, as map-metrics ('pcmapq eval' uses "
                           f"{EVAL_NOREF_VOXEL:g})."}),
    Option("noref_sample", "noref.sample", INT,
           "MME and MPV of a 3D cloud are means over this many of its points drawn at random "
           "(seeded), their standard errors reported, and MOM's planes are found on the cloud "
           "at a third of the radius (0: every point, as 'pcmapq inspect').", 0,
           commands=(EVAL, BATCH, INSPECT),
           helps={INSPECT: "MME and MPV over this many points drawn at random (seeded), with "
                           "their standard errors, and MOM's planes from the cloud at a third "
                           "of the radius; 0: every point, as map-metrics ('pcmapq eval' uses "
                           f"{EVAL_NOREF_SAMPLE})."}),
    Option("noref_min_knn", "noref.min_knn", INT,
           "A point counts when it has more than this many neighbours.", 0,
           commands=(INSPECT,)),
    Option("noref_max_nn", "noref.max_nn", INT,
           "Nearest neighbours of the normals that pick MOM's orthogonal planes.", 3,
           commands=(INSPECT,)),
    Option("structures", "structures.enabled", SWITCH,
           "Two 3D clouds: also find their planes and the lines where two planes meet, and "
           "match them one to one (quality, precision, f1, displacements).",
           flag="--structures/--no-structures"),
    Option("structures_voxel", "structures.voxel", FLOAT,
           "3D structures: each cloud is reduced to one point per voxel of this side before "
           "its planes are found, metres (coarser: fewer, larger planes, sooner).", 0.01),
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
    Option("line_length", "structures.line_length", FLOAT,
           "3D structures: the shortest line where two planes meet that is counted, metres "
           "(shorter ones, where two planes barely touch, come and go with each pass).", 0.0),
)


def options_of(command: str | None = None) -> tuple[Option, ...]:
    """The options ``command`` takes (None: every option), in table order. Read when called,
    not when imported, so that an option added to :data:`OPTIONS` reaches every reader."""
    return tuple(o for o in OPTIONS if command is None or command in o.commands)


def option_named(name: str) -> Option:
    """The option of this name (KeyError when none)."""
    return {o.name: o for o in OPTIONS}[name]
