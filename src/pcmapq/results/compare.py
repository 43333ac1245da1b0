"""``pcmapq compare``: saved results (``eval --json``, or a batch's per-map JSONs) side by side,
like evo_res. They must share a truth (the same file: the same SHA-256 when both results
record it, else the same path, resolved from here; and the same grid shape, resolution and
origin) unless told otherwise; each becomes one row of the comparison table and figure
(report/summary.py)."""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from pydantic import ValidationError

from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.io.writers import one_line
from pcmapq.results.rows import table_row
from pcmapq.results.schema import ResultDocument, problem

#: What makes two truths the same, beside their path: the truth grid's keys in the JSON.
TRUTH_GRID = ("shape", "resolution_m", "origin")
#: Settings (dotted names, or their groups) that differ between results without changing what
#: a figure means: each map's own source and pose guess, and which figures were computed.
OWN_SETTINGS = ("map", "alignment.init", "alignment.init_3d", "matching.detectors")
#: Settings named in the warning, at most.
NAMED_SETTINGS = 3


@dataclass(frozen=True)
class Saved:
    """One saved result: its file, the row name, the parsed document and its table row."""

    path: Path
    name: str
    doc: dict
    row: dict[str, object]


def read_results(paths: Sequence[Path], names: Sequence[str] | None = None) -> list[Saved]:
    """Read every result JSON; name its row ``names[i]``, else the file's stem (its path
    without the suffix when two stems are alike). A file that cannot be read, is not JSON or
    is not a pcmapq eval result is an InputError naming it."""
    if names is not None and len(names) != len(paths):
        raise InputError(f"--names gives {count(len(names), 'name')} for "
                         f"{count(len(paths), 'result')}")
    if names is None:
        stems = [p.stem for p in paths]
        names = [s if stems.count(s) == 1 else str(p.with_suffix(""))
                 for s, p in zip(stems, paths, strict=True)]
    return [_read(path, name) for path, name in zip(paths, names, strict=True)]


def truth_differences(results: Sequence[Saved]) -> list[str]:
    """The results whose truth differs from the first's, each as 'file (what differs)': the
    file (its SHA-256 when both record one, else its resolved path) or the grid."""
    first = _truth_key(results[0].doc)
    out = []
    for saved in results[1:]:
        key = _truth_key(saved.doc)
        (path_a, digest_a, *grid_a), (path_b, digest_b, *grid_b) = first, key
        what = (["sha256"] if digest_a and digest_b and digest_a != digest_b else
                ["path"] if not (digest_a and digest_b) and path_a != path_b else [])
        what += [field for field, a, b in zip(TRUTH_GRID, grid_a, grid_b, strict=True)
                 if a != b]
        if what:
            out.append(f"{saved.path} ({', '.join(what)})")
    return out


def check_same_truth(results: Sequence[Saved], allow_different: bool) -> str | None:
    """Refuse (InputError) results that do not share the first's truth, in one line naming
    them; with ``allow_different``, that line as a warning to show instead (None when they
    all share it)."""
    differ = truth_differences(results)
    if not differ:
        return None
    line = (f"{len(differ)} of {count(len(results), 'result')} have another truth than "
            f"{results[0].path} ({results[0].doc['truth']['path']}): {'; '.join(differ)}")
    if not allow_different:
        raise InputError(line + " (--allow-different-truths to compare them anyway)")
    return line


def settings_differences(results: Sequence[Saved]) -> list[str]:
    """The settings whose recorded values differ among the results, each as 'name (value in
    files; value in files)', in name order; a setting a result does not record (saved before
    it was one) is 'not recorded'. Not those of :data:`OWN_SETTINGS` nor the switches
    (``*.enabled``): they leave every figure's meaning as it is. A group a result has none of
    (``map_3d`` and ``structures`` but for two 3D clouds) is compared among the others."""
    groups = [saved.doc.get("settings", {}) for saved in results]
    flat = [_flat(group) for group in groups]
    out = []
    for key in sorted(set().union(*flat)):
        if key.endswith(".enabled") or any(key == own or key.startswith(own + ".")
                                           for own in OWN_SETTINGS):
            continue
        having = [(saved, f) for saved, f, g in zip(results, flat, groups, strict=True)
                  if key.split(".")[0] in g]
        values = [json.dumps(f[key], sort_keys=True) if key in f else "not recorded"
                  for _, f in having]
        if len(set(values)) > 1:
            held = [f"{v} in " + ", ".join(str(saved.path) for (saved, _), w
                                           in zip(having, values, strict=True) if w == v)
                    for v in dict.fromkeys(values)]
            out.append(f"{key} ({'; '.join(held)})")
    return out


def check_same_settings(results: Sequence[Saved]) -> str | None:
    """A warning line naming the settings the results were scored with that differ (at most
    :data:`NAMED_SETTINGS` of them; None when they agree): the same figure under other
    settings may not compare."""
    differ = settings_differences(results)
    if not differ:
        return None
    more = len(differ) - NAMED_SETTINGS
    rest = f" and {count(more, 'more setting')}" if more > 0 else ""
    return (f"results scored with other settings: {', '.join(differ[:NAMED_SETTINGS])}{rest}; "
            "their figures may not compare")


def _flat(doc: dict, prefix: str = "") -> dict[str, object]:
    """A nested settings record as dotted names and their values (lists kept whole)."""
    out: dict[str, object] = {}
    for key, value in doc.items():
        if isinstance(value, dict):
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def _read(path: Path, name: str) -> Saved:
    """One result JSON and its row; InputError naming the file when it is not one."""
    try:
        doc = json.loads(Path(path).read_bytes())
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {one_line(exc)}") from None
    except ValueError as exc:  # not UTF-8 or not JSON
        raise InputError(f"{path}: not a JSON file: {one_line(exc)}") from None
    try:
        if not isinstance(doc, dict) or "pcmapq" not in doc:
            raise ValueError("no 'pcmapq' section")
        ResultDocument.model_validate(doc)
        row = table_row(name, doc)
        _truth_key(doc)
    except ValidationError as exc:
        raise InputError(f"{path}: not a pcmapq eval result: {problem(exc)}") from None
    except (ValueError, TypeError, KeyError) as exc:
        raise InputError(f"{path}: not a pcmapq eval result: {one_line(exc)}") from None
    return Saved(Path(path), name, doc, row)


def _truth_key(doc: dict) -> tuple:
    """The truth's path (resolved from the current folder, as the user typed it to eval or
    batch wrote it), its SHA-256 (None when not recorded) and grid (None for what the JSON
    lacks)."""
    truth = doc["truth"]
    grid = tuple(json.dumps(truth.get(k), sort_keys=True) for k in TRUTH_GRID)
    return (os.path.realpath(str(truth["path"])), truth.get("sha256"), *grid)
