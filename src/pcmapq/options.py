"""The command line's option text turned into typed values (typer.BadParameter on bad text),
the command line rebuilt from its parsed options, and the checks that refuse, before any work,
outputs that cannot be written and options that cannot work together (InputError, exit 2)."""

from __future__ import annotations

import math
import os
import shlex
import stat
from collections.abc import Iterable
from dataclasses import replace
from pathlib import Path

import numpy as np
import typer

from pcmapq.core.errors import InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.io import Thresholds
from pcmapq.io.occupancy import IMAGE_SUFFIXES, YAML_SUFFIXES, read_yaml
from pcmapq.io.writers import same_file
from pcmapq.raster.footprint import FOOTPRINT_RULES
from pcmapq.settings import DETECTOR_NAMES, DistancesConfig, MatchingConfig, Settings, SourceConfig


def command_line(ctx: typer.Context) -> str:
    """The command as given, rebuilt from its parsed parameters (defaults left out), so a saved
    result says how it was made: ``pcmapq eval MAP TRUTH --option value ...``."""
    words = ["pcmapq", ctx.info_name or "eval"]
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        source = ctx.get_parameter_source(param.name)
        if source is None or source.name == "DEFAULT" or value is None:
            continue
        if param.param_type_name == "argument":
            words += [str(v) for v in (value if isinstance(value, (list, tuple)) else [value])]
        elif isinstance(value, bool) and param.is_flag:
            if value or param.secondary_opts:
                words.append(param.opts[0] if value else param.secondary_opts[0])
        else:
            words += [param.opts[0], str(value)]
    return shlex.join(words)


def finite(param: typer.CallbackParam, value: float | None) -> float | None:
    """A float option's callback: refuse 'inf' and 'nan', which click's FLOAT reads."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"expected a finite number, got {value}",
                                 param_hint=param.opts[0] if param.opts else None)
    return value


def parse_init(text: str | None) -> Similarity2D | None:
    """--init ``x,y,yaw`` (metres, metres, degrees; finite) as a map -> truth guess."""
    if text is None:
        return None
    try:
        x, y, yaw = (float(v) for v in text.split(","))
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(text)
    except ValueError:
        raise typer.BadParameter(f"expected finite x,y,yaw (metres, metres, degrees), got "
                                 f"{text!r}", param_hint="--init") from None
    return Similarity2D(x, y, float(np.radians(yaw)))


def parse_box(text: str | None, option: str) -> tuple[float, float, float, float] | None:
    """--map-crop / --truth-crop ``x0,y0,x1,y1`` (metres, finite, x0 < x1, y0 < y1)."""
    if text is None:
        return None
    try:
        x0, y0, x1, y1 = (float(v) for v in text.split(","))
        if not (all(math.isfinite(v) for v in (x0, y0, x1, y1)) and x0 < x1 and y0 < y1):
            raise ValueError(text)
    except ValueError:
        raise typer.BadParameter(f"expected a box x0,y0,x1,y1 in metres with x0 < x1 and "
                                 f"y0 < y1, got {text!r}", param_hint=option) from None
    return x0, y0, x1, y1


def parse_resolution(text: str | None, scale: str) -> tuple[float | None, bool]:
    """(--map-resolution as metres or None, whether to estimate the scale)."""
    if scale not in ("fixed", "auto"):
        raise typer.BadParameter(f"expected 'fixed' or 'auto', got {scale!r}", param_hint="--scale")
    if text is None or text == "auto":
        return None, scale == "auto" or text == "auto"
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 < value < math.inf:
        raise typer.BadParameter(f"expected metres per pixel or 'auto', got {text!r}",
                                 param_hint="--map-resolution")
    return value, scale == "auto"


def thresholds(occupied: float | None, free: float | None,
                negate: bool | None) -> Thresholds | None:
    """map_server overrides from the command line (None when none is given)."""
    if occupied is None and free is None and negate is None:
        return None
    return Thresholds(occupied, free, negate)


def parse_taus(text: str) -> tuple[float, ...]:
    """--tau ``M,M,...``: positive finite distances, metres."""
    try:
        taus = tuple(float(v) for v in text.split(","))
    except ValueError:
        taus = ()
    if not taus or not all(0 < t < math.inf for t in taus):
        raise typer.BadParameter(f"expected positive finite distances in metres, got {text!r}",
                                 param_hint="--tau")
    return taus


def parse_detectors(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    unknown = [n for n in names if n not in DETECTOR_NAMES]
    if unknown or not names:
        raise typer.BadParameter(f"unknown detector(s) {unknown}; choose from "
                                 f"{','.join(DETECTOR_NAMES)}", param_hint="--detectors")
    return names


def parse_footprint(text: str) -> str:
    if text not in FOOTPRINT_RULES:
        raise typer.BadParameter(f"expected one of {', '.join(FOOTPRINT_RULES)}, got {text!r}",
                                 param_hint="--footprint")
    return text


#: What each output option writes, by extension (``--aligned``: see :func:`output_suffixes`).
OUTPUT_SUFFIXES = {"--json": (".json",), "--vectors": (".csv",), "--regions": (".csv",),
                   "--plot": (".png", ".svg", ".pdf"), "--report": (".html", ".htm"),
                   "--transform": (".txt",), "--distances": (".ply",),
                   "--out": (".ply", ".pcd"), "--poses-out": (".txt", ".kitti"),
                   "--tum-out": (".txt", ".tum")}
#: ``--aligned`` of an image map (a map_server image, its YAML beside it) and of a cloud.
ALIGNED_IMAGE, ALIGNED_CLOUD = (".png", ".pgm"), (".ply", ".pcd")


def output_suffixes(option: str, map_path: Path | None) -> tuple[str, ...]:
    """The extensions ``option`` may write; ``--aligned`` writes the map's kind (an image for
    an image or YAML map, a cloud otherwise, or for a map built from scans: ``map_path`` None)."""
    if option != "--aligned":
        return OUTPUT_SUFFIXES[option]
    image = map_path is not None and map_path.suffix.lower() in IMAGE_SUFFIXES + YAML_SUFFIXES
    return ALIGNED_IMAGE if image else ALIGNED_CLOUD


#: Folders of device and process files (``/dev/stdout`` and its like): no output is written
#: there (``--json -`` is stdout), except in the ordinary files of ``/dev/shm``.
SPECIAL_FOLDERS, ORDINARY_FOLDER = (Path("/dev"), Path("/proc")), Path("/dev/shm")


def kept(path: str | Path | None) -> str | Path | None:
    """An output option's path, or None (nothing written) for ``/dev/null`` (``os.devnull``),
    as Unix tools read it: never written through (an atomic write would replace the device)."""
    return None if path is not None and str(path) == os.devnull else path


def check_outputs(outputs: dict[str, str | Path | None], map_path: Path | None,
                  inputs: Iterable[Path | None] = ()) -> None:
    """Refuse, before any work, an output that could not be written: ``outputs`` maps each
    option (``--json`` ...) to its path or None (``--json -`` is stdout). Each path needs a
    known extension, an existing writable folder (a symlink's: it is written through), no
    folder, device, FIFO or socket in its place, no other output on it (an ``--aligned``
    image's YAML included), and must not be one of the ``inputs`` (nor the YAML beside an input
    image, nor the image an input YAML names)."""
    read = [f for given in inputs if given is not None for f in input_files(Path(given))]
    taken: dict[Path, str] = {}
    for option, given in outputs.items():
        if given is None or str(given) == "-":
            continue
        path = Path(given)
        suffixes = output_suffixes(option, map_path)
        if path.suffix.lower() not in suffixes:
            raise InputError(f"{path}: {option} writes {_alternatives(suffixes)}, not "
                             f"'{path.suffix or path.name}'")
        _check_target(option, path)
        written = [path] + ([path.with_suffix(".yaml")] if suffixes == ALIGNED_IMAGE else [])
        for target in written:
            if (source := next((f for f in read if same_file(target, f)), None)) is not None:
                raise InputError(f"{target}: {option} would overwrite the input '{source}'")
            key = target.resolve()
            if key in taken:
                raise InputError(f"{target}: written by both {taken[key]} and {option}")
            taken[key] = option


def _check_target(option: str, path: Path) -> None:
    """Refuse an output path that is a folder or a special file, or whose folder (through a
    symlink: its target's) is missing or not writable."""
    real = Path(os.path.realpath(path))
    for place in [*_link_chain(path), real]:
        if any(place.is_relative_to(folder) for folder in SPECIAL_FOLDERS) and \
                not place.is_relative_to(ORDINARY_FOLDER):
            raise InputError(f"{path}: {option}: a device or process file, not a regular file"
                             + (" (--json - writes to stdout)" if option == "--json" else ""))
    folder = real.parent
    if not folder.is_dir():
        raise InputError(f"{path}: {option}: folder '{folder}' does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{path}: {option}: folder '{folder}' is not writable")
    if real.is_dir():
        raise InputError(f"{path}: {option}: is a folder")
    if real.exists() and not stat.S_ISREG(real.stat().st_mode):
        raise InputError(f"{path}: {option}: not a regular file (a FIFO, device or socket)")


def _link_chain(path: Path, hops: int = 40) -> list[Path]:
    """``path`` and every path its symlinks lead through (absolute, normalised): a link to
    ``/dev/stdout`` passes ``/dev`` even when its end is a regular file."""
    chain = [Path(os.path.abspath(path))]
    while chain[-1].is_symlink() and len(chain) <= hops:
        chain.append(Path(os.path.abspath(chain[-1].parent / os.readlink(chain[-1]))))
    return chain


def input_files(path: Path) -> list[Path]:
    """The files an input path reads: itself, the map_server YAML beside an image (same
    stem), the image a YAML names (when it parses)."""
    suffix = path.suffix.lower()
    if suffix in IMAGE_SUFFIXES:
        return [path] + [path.with_suffix(s) for s in YAML_SUFFIXES]
    if suffix in YAML_SUFFIXES:
        try:
            return [path, read_yaml(path)[1]]
        except InputError:
            return [path]
    return [path]


def check_eval_options(*, scans: Path | None, max_scans: int | None, no_align: bool,
                       auto_scale: bool) -> None:
    """Refuse options of ``pcmapq eval`` that cannot work together."""
    if max_scans is not None and scans is None:
        raise InputError("--max-scans N: only with --scans DIR (the scans to map)")
    if no_align and auto_scale:
        raise InputError("--no-align and --scale auto (or --map-resolution auto) cannot go "
                         "together: estimating the scale is part of the alignment")


def _alternatives(suffixes: tuple[str, ...]) -> str:
    """``.png, .svg or .pdf``."""
    return suffixes[0] if len(suffixes) == 1 else \
        f"{', '.join(suffixes[:-1])} or {suffixes[-1]}"


def eval_settings(values: dict[str, object]) -> Settings:
    """The Settings of ``pcmapq eval`` from its options by parameter name (``threshold``,
    ``map_resolution``, ``noref_voxel`` ...; a name left out takes eval's default): the one
    place eval and each row of a batch build them."""
    d = Settings()
    v = values.get
    resolution, auto = parse_resolution(v("map_resolution"), v("scale") or "fixed")
    return Settings(
        map=SourceConfig(resolution, thresholds(
            v("map_occupied_thresh"), v("map_free_thresh"), v("map_negate")),
            parse_box(v("map_crop"), "--map-crop")),
        truth=SourceConfig(v("truth_resolution"), thresholds(
            v("truth_occupied_thresh"), v("truth_free_thresh"), v("truth_negate")),
            parse_box(v("truth_crop"), "--truth-crop")),
        raster=replace(d.raster, band_low=v("band_low", d.raster.band_low),
                       band_high=v("band_high", d.raster.band_high), min_hits=v("min_hits")),
        alignment=replace(d.alignment, enabled=not v("no_align"), init=parse_init(v("init")),
                          scale=auto, voxel_3d=v("voxel_3d", d.alignment.voxel_3d),
                          force=bool(v("force"))),
        footprint=replace(d.footprint, rule=parse_footprint(v("footprint", d.footprint.rule)),
                          full=bool(v("full"))),
        matching=MatchingConfig(
            parse_detectors(v("detectors", ",".join(d.matching.detectors))),
            v("threshold", d.matching.threshold)),
        distances=DistancesConfig(parse_taus(
            v("tau", ",".join(f"{t:g}" for t in d.distances.taus)))),
        noref=replace(d.noref, enabled=v("noref", d.noref.enabled),
                      radius=v("noref_radius", d.noref.radius),
                      voxel=v("noref_voxel", d.noref.voxel)))
