"""Output paths checked before any work: each output option's path must have a known
extension, a writable folder, no device or folder in its place, and must not overwrite an
input or another output (InputError, exit 2). ``/dev/null`` discards an output."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from pathlib import Path

from pcmapq.core.errors import InputError
from pcmapq.io.formats import IMAGE_SUFFIXES, YAML_SUFFIXES
from pcmapq.io.map_yaml import read_yaml
from pcmapq.io.writers import same_file

#: What each output option writes, by extension (``--aligned``: see :func:`output_suffixes`).
OUTPUT_SUFFIXES = {"--json": (".json",), "--vectors": (".csv",), "--regions": (".csv",),
                   "--regions-3d": (".csv",),
                   "--plot": (".png", ".svg", ".pdf"), "--report": (".html", ".htm"),
                   "--transform": (".txt",), "--distances": (".ply", ".las", ".laz"),
                   "--out": (".ply", ".pcd"), "--poses-out": (".txt", ".kitti"),
                   "--tum-out": (".txt", ".tum")}
#: ``--aligned`` of an image map (a map_server image, its YAML beside it) and of a cloud.
ALIGNED_IMAGE, ALIGNED_CLOUD = (".png", ".pgm"), (".ply", ".pcd", ".las", ".laz")


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


def _alternatives(suffixes: tuple[str, ...]) -> str:
    """``.png, .svg or .pdf``."""
    return suffixes[0] if len(suffixes) == 1 else \
        f"{', '.join(suffixes[:-1])} or {suffixes[-1]}"
