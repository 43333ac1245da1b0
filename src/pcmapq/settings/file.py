"""Settings files (``--config FILE``, as KISS-ICP's): YAML holding any part of
:meth:`Settings.to_dict <pcmapq.settings.Settings.to_dict>`'s document, one group per stage,
metres and degrees; ``pcmapq config --dump`` writes every setting with its value. What a
file leaves out keeps its default; options on the command line override the file."""

from __future__ import annotations

import copy
import difflib
import math
from pathlib import Path
from typing import Any

import yaml

from pcmapq.core.errors import InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.io.map_yaml import Thresholds
from pcmapq.io.writers import one_line
from pcmapq.settings.build import check
from pcmapq.settings.configs import Settings
from pcmapq.settings.plain import plain
from pcmapq.settings.table import FLOAT, INT, SWITCH, TEXT, OptionError, options_of

#: Groups that are null by default and take these keys when a file gives them.
NULL_GROUPS = {"thresholds": {"occupied": None, "free": None, "negate": None},
               "init": Similarity2D().to_dict()}


def dump_settings(settings: Settings) -> str:
    """Every setting as YAML, in :meth:`Settings.to_dict`'s order."""
    return yaml.safe_dump(settings.to_dict(), sort_keys=False)


def changed_settings(settings: Settings, base: Settings) -> dict:
    """The settings of ``settings`` that differ from ``base``'s, as :meth:`Settings.to_dict`
    nests them (a list whole); empty when none do."""
    def diff(new: dict, old: dict) -> dict:
        out = {}
        for key, value in new.items():
            if isinstance(value, dict) and isinstance(old.get(key), dict):
                inner = diff(value, old[key])
                if inner:
                    out[key] = inner
            elif value != old.get(key):
                out[key] = value
        return out

    return diff(settings.to_dict(), base.to_dict())


def read_settings(path: str | Path, base: Settings | None = None) -> Settings:
    """``base`` (default: ``Settings()``) with the settings of the YAML file at ``path`` over
    it (``pcmapq.read_settings``). A word option takes its command line's text
    (``alignment: {scale: auto}``). An unreadable file, an unknown key, a value of the wrong
    kind or out of its option's bounds: InputError naming the file and the key."""
    base = Settings() if base is None else base
    try:
        doc = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read: {getattr(exc, 'strerror', None) or exc}"
                         ) from None
    except yaml.YAMLError as exc:
        raise InputError(f"{path}: not YAML: {one_line(exc)}") from None
    if doc is None:
        return base
    if not isinstance(doc, dict):
        raise InputError(f"{path}: expected a mapping of settings groups (map, truth, raster, "
                         "alignment, footprint, matching, distances, noref, map_3d, "
                         "structures)")
    merged = _merge(base.to_dict(), _read_words(doc, path), path, "")
    for option in options_of():
        _check_option(merged, option, path)
    try:
        settings = Settings.from_dict(merged)
    except (TypeError, ValueError, KeyError) as exc:
        raise InputError(f"{path}: {one_line(exc)}") from None
    try:
        check(settings)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    return settings


def _read_words(doc: dict, path: str | Path) -> dict:
    """``doc`` with each word option given as text (``scale: auto``, ``resolution: auto``,
    ``init: "1,2,30"``, ``detectors: harris,hough``; ``init_3d`` also as the list of 16 numbers
    a result saves) read by its option's parser, as the command line reads it, and the
    settings that value implies (``also``) set too."""
    out = copy.deepcopy(doc)
    for option in options_of():
        if option.kind != TEXT:
            continue
        *groups, key = option.path.split(".")
        group = _group(out, groups)
        if group is not None and option.path == "alignment.init_3d" and \
                isinstance(group.get(key), list):  # a matrix as a saved result lists it
            group[key] = ",".join(str(v) for v in group[key])
        if group is None or not isinstance(group.get(key), str):
            continue
        try:
            setting = option.read(group[key])
        except OptionError as exc:
            raise InputError(f"{path}: {option.path}: {exc.message}") from None
        group[key] = plain(setting)
        for also, value in option.also(setting).items():
            *also_groups, also_key = also.split(".")
            target = _group(out, also_groups, make=True)
            if target is not None:
                target[also_key] = plain(value)
    return out


def _group(doc: dict, steps: list[str], make: bool = False) -> dict | None:
    """The group of ``doc`` at ``steps`` (made empty when absent and ``make``); None when a
    step is absent or not a group."""
    for step in steps:
        if make and step not in doc:
            doc[step] = {}
        doc = doc.get(step)
        if not isinstance(doc, dict):
            return None
    return doc


def _merge(into: dict, doc: dict, path: Path, where: str) -> dict:
    """``into`` with ``doc``'s values over it; a key ``into`` lacks, or a value of another
    kind than its default's, is refused."""
    out = dict(into)
    for key, value in doc.items():
        here = f"{where}{key}"
        if key not in into:
            close = difflib.get_close_matches(str(key), [str(k) for k in into], n=1)
            hint = f" (did you mean '{where}{close[0]}'?)" if close else ""
            raise InputError(f"{path}: unknown setting '{here}'{hint}")
        default = into[key]
        if default is None and str(key) in NULL_GROUPS and isinstance(value, dict):
            default = NULL_GROUPS[str(key)]
        if isinstance(default, dict) and value is not None:
            if not isinstance(value, dict):
                raise InputError(f"{path}: {here}: expected a group of settings, got {value!r}")
            out[key] = _merge(default, value, path, here + ".")
        else:
            _check_kind(default, value, path, here)
            out[key] = float(value) if isinstance(default, float) and isinstance(value, int) \
                else value
    return out


def _check_kind(default: Any, value: Any, path: Path, where: str) -> None:
    """Refuse a value of another kind than its default's (a null default takes any)."""
    if default is None or value is None:
        return
    if isinstance(default, bool):
        ok = isinstance(value, bool)
    elif isinstance(default, int | float):
        ok = (isinstance(value, int | float) and not isinstance(value, bool)
              and math.isfinite(value) and (isinstance(default, float) or
                                            isinstance(value, int)))
    else:
        ok = isinstance(value, type(default))
    if not ok:
        raise InputError(f"{path}: {where}: expected {_kind(default)}, got {value!r}")


def _check_option(doc: dict, option, path: Path) -> None:
    """Refuse a value the option of its setting would refuse on the command line."""
    value: Any = doc
    for step in option.path.split("."):
        if not isinstance(value, dict) or step not in value:
            return
        value = value[step]
    if value is None:
        return
    where = f"{path}: {option.path}"
    if option.kind in (FLOAT, INT) and not option.lo <= value <= option.hi:
        raise InputError(f"{where}: expected a number{option.bounds}, got {value!r}")
    if option.kind == TEXT:
        try:
            option.read(option.show(_setting(option.path, value)))
        except (OptionError, TypeError, ValueError) as exc:
            raise InputError(f"{where}: {getattr(exc, 'message', exc)}") from None
    if option.kind == SWITCH and not isinstance(value, bool):
        raise InputError(f"{where}: expected true or false, got {value!r}")


def _setting(path: str, value: Any) -> Any:
    """A file's value as the setting the option shows (lists as tuples, ``init`` as a pose)."""
    if path == "alignment.init":
        return Similarity2D.from_dict(value)
    if path.endswith(".thresholds"):
        return Thresholds(**value)
    return tuple(value) if isinstance(value, list) else value


def _kind(default: Any) -> str:
    if isinstance(default, bool):
        return "true or false"
    if isinstance(default, int):
        return "an integer"
    if isinstance(default, float):
        return "a number"
    if isinstance(default, list):
        return "a list"
    return "text" if isinstance(default, str) else type(default).__name__
