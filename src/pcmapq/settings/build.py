"""Settings built from options: a base (the defaults, or a settings file) with the options a
user gave applied by the option table (:mod:`pcmapq.settings.table`), then the checks of
options that cannot work together."""

from __future__ import annotations

import typing
from dataclasses import MISSING, fields, is_dataclass, replace
from typing import Any

from pcmapq.core.errors import InputError
from pcmapq.settings.configs import NoRefConfig, Settings
from pcmapq.settings.table import SWITCH, Option, options_of


def base_settings(command: str) -> Settings:
    """A command's defaults: eval's, but ``inspect``'s no-reference figures of a cloud as it
    is (no voxel), as map-metrics computes them."""
    return Settings(noref=NoRefConfig()) if command == "inspect" else Settings()


def default_of(command: str, path: str) -> Any:
    """The setting at a dotted ``path`` as :func:`base_settings` holds it for ``command``, read
    from the dataclasses' field defaults (:func:`field_default`): the defaults the help shows
    load no detector."""
    if command == "inspect" and path.startswith("noref."):
        return field_default(NoRefConfig, path.partition(".")[2])
    return field_default(Settings, path)


def field_default(owner: type, path: str) -> Any:
    """The default of the field at a dotted ``path`` of the dataclass ``owner``; a group whose
    factory is its class is not made (``MatchingConfig()`` would load every detector for its
    ``params``), its fields are read instead."""
    step, _, rest = path.partition(".")
    found = {f.name: f for f in fields(owner)}[step]
    factory = found.default_factory
    if found.default is not MISSING:
        value = found.default
    elif rest and isinstance(factory, type) and is_dataclass(factory):
        return field_default(factory, rest)
    else:
        value = factory()  # type: ignore[misc]
    return get_path(value, rest) if rest else value


def get_path(settings: Any, path: str) -> Any:
    """The setting at a dotted ``path`` (None past a group that is None)."""
    value = settings
    for step in path.split("."):
        if value is None:
            return None
        value = getattr(value, step)
    return value


def set_path(settings: Any, path: str, value: Any) -> Any:
    """``settings`` with the setting at a dotted ``path`` replaced; a group that is None (map
    image thresholds) is made with its defaults first."""
    step, _, rest = path.partition(".")
    if not rest:
        return replace(settings, **{step: value})
    group = getattr(settings, step)
    if group is None:
        group = _group_type(type(settings), step)()
    return replace(settings, **{step: set_path(group, rest, value)})


def build(values: dict[str, Any], command: str, base: Settings | None = None) -> Settings:
    """``base`` (default: :func:`base_settings`) with each option of ``command`` in ``values``
    (by name; None or absent: not given) read and applied, in table order; then
    :func:`check`. OptionError on a value that cannot be read."""
    settings = base_settings(command) if base is None else base
    for option in options_of(command):
        if values.get(option.name) is not None:
            settings = apply(settings, option, values[option.name])
    check(settings)
    return settings


def apply(settings: Settings, option: Option, value: Any) -> Settings:
    """``settings`` with one option's value (as the command line gives it) applied."""
    setting = option.read(value)
    settings = set_path(settings, option.path, setting)
    for path, also in option.also(setting).items():
        settings = set_path(settings, path, also)
    return settings


def check(settings: Settings) -> None:
    """Refuse settings that cannot work together (InputError, one line)."""
    option = settings.alignment
    if not option.enabled and option.scale:
        raise InputError("--no-align and --scale auto (or --map-resolution auto) cannot go "
                         "together: estimating the scale is part of the alignment")
    if option.init_3d is None:
        return
    other = ("--init" if option.init is not None else "--no-align" if not option.enabled else
             "--scale auto (or --map-resolution auto)" if option.scale else None)
    if other is not None:
        raise InputError(f"--init-3d and {other} cannot go together: --init-3d starts the "
                         "rigid 3D registration of two 3D clouds")


def option_words(values: dict[str, Any], command: str) -> list[str]:
    """The options among ``values`` (by name, as given) as the command line shows them, in
    table order: a switch as its ``--x`` or its ``--no-x``."""
    words: list[str] = []
    for option in options_of(command):
        value = values.get(option.name)
        if value is None:
            continue
        if option.kind == SWITCH:
            on, off = (option.flag or "").split("/")
            words.append(on if value else off)
        else:
            words += [option.option, str(value)]
    return words


def _group_type(owner: type, name: str) -> type:
    """The dataclass a field ``name`` of ``owner`` holds (``Thresholds | None``)."""
    hint = typing.get_type_hints(owner)[name]
    kinds = [k for k in typing.get_args(hint) or (hint,) if is_dataclass(k)]
    if not kinds:
        raise TypeError(f"{owner.__name__}.{name} is not a group of settings")
    return kinds[0]
