"""The command line's options: the settings options of a command made from the option table
(:mod:`pcmapq.settings.table`) with ``--config FILE`` and, hidden, the former names it still
reads; the Settings a command's parsed options give, and the command line rebuilt from them."""

from __future__ import annotations

import functools
import inspect
import math
import shlex
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from pcmapq.settings import Settings
from pcmapq.settings.build import base_settings, build, default_of
from pcmapq.settings.file import read_settings
from pcmapq.settings.renamed import Renamed, renamed_of
from pcmapq.settings.table import (
    FLOAT,
    INT,
    SWITCH,
    Option,
    OptionError,
    option_named,
    options_of,
)

#: Python types of the option kinds, as typer reads them.
TYPES = {FLOAT: float | None, INT: int | None, SWITCH: bool | None}
#: ``--config``: a settings file (``pcmapq config --dump`` writes one).
CONFIG_HELP = ("Settings file (YAML, as 'pcmapq config --dump' writes): its settings replace "
               "the defaults; options given here override it.")


def command_line(ctx: typer.Context) -> str:
    """The command as given, rebuilt from its parsed parameters (defaults left out), so a saved
    result says how it was made: ``pcmapq eval MAP TRUTH --option value ...``; an option given
    by its former name is written by its name."""
    words = ["pcmapq", ctx.info_name or "eval"]
    now = {r.old: option_named(r.new).option for r in renamed_of(ctx.info_name or "eval")}
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
            words += [now.get(param.name or "", param.opts[0]), str(value)]
    return shlex.join(words)


def finite(param: typer.CallbackParam, value: float | None) -> float | None:
    """A float option's callback: refuse 'inf' and 'nan', which click's FLOAT reads."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"expected a finite number, got {value}",
                                 param_hint=param.opts[0] if param.opts else None)
    return value


def settings_options(command: str) -> Callable:
    """A decorator that gives a typer command ``--config`` and the settings options of
    ``command`` from the option table, after its own: the command takes them as
    ``**settings_values`` and builds its Settings with :func:`settings_of`."""
    def wrap(func: Callable) -> Callable:
        signature = inspect.signature(func, eval_str=True)
        own = [p for p in signature.parameters.values() if p.kind != p.VAR_KEYWORD]
        extra = [inspect.Parameter("config", inspect.Parameter.KEYWORD_ONLY, default=None,
                                   annotation=Annotated[Path | None, typer.Option(
                                       help=CONFIG_HELP, metavar="FILE")])]
        extra += [_parameter(o, command) for o in options_of(command)]
        extra += [_former(r) for r in renamed_of(command)]

        @functools.wraps(func)
        def command_function(*args: Any, **kwargs: Any) -> Any:
            return func(*args, **kwargs)

        command_function.__signature__ = signature.replace(  # type: ignore[attr-defined]
            parameters=own + extra)
        return command_function
    return wrap


def settings_of(ctx: typer.Context, command: str, values: dict[str, Any]) -> Settings:
    """The Settings of ``command``: its defaults, or the ``--config`` file over them, with the
    table's options given on the command line applied. A value that cannot be read is a
    usage error naming its option."""
    given = {name: value for name, value in values.items() if name != "config" and
             getattr(ctx.get_parameter_source(name), "name", "") in ("COMMANDLINE", "ENVIRONMENT")}
    given = _renamed(given, command)
    config = values.get("config")
    base = base_settings(command) if config is None else read_settings(config,
                                                                       base_settings(command))
    try:
        return build(given, command, base)
    except OptionError as exc:
        raise typer.BadParameter(exc.message, param_hint=exc.option) from None


def _parameter(option: Option, command: str) -> inspect.Parameter:
    """The typer parameter of one table option; its default is the setting's default."""
    default = option.show(default_of(command, option.path))
    kind = TYPES.get(option.kind, str | None)
    decls = [option.flag] if option.flag else []
    bounds = {k: v for k, v in (("min", option.lo), ("max", option.hi)) if math.isfinite(v)}
    info = typer.Option(*decls, help=option.help_for(command), metavar=option.metavar,
                        show_default=default is not None and default is not False,
                        callback=finite if option.kind == FLOAT else None,
                        **(bounds if option.kind in (FLOAT, INT) else {}))
    return inspect.Parameter(option.name, inspect.Parameter.KEYWORD_ONLY,
                             default=default, annotation=Annotated[kind, info])


def _former(renamed: Renamed) -> inspect.Parameter:
    """The hidden parameter of an option's former name: read as the option is, no default."""
    option = option_named(renamed.new)
    bounds = {k: v for k, v in (("min", option.lo), ("max", option.hi)) if math.isfinite(v)}
    info = typer.Option(renamed.option, hidden=True, metavar=option.metavar,
                        callback=finite if option.kind == FLOAT else None,
                        **(bounds if option.kind in (FLOAT, INT) else {}))
    return inspect.Parameter(renamed.old, inspect.Parameter.KEYWORD_ONLY, default=None,
                             annotation=Annotated[TYPES.get(option.kind, str | None), info])


def _renamed(given: dict[str, Any], command: str) -> dict[str, Any]:
    """``given`` with each option given by its former name under its name, and a warning
    naming it; a usage error when both names are given."""
    out = dict(given)
    for renamed in renamed_of(command):
        if renamed.old not in out:
            continue
        now = option_named(renamed.new).option
        if renamed.new in out:
            raise typer.BadParameter(f"give it once ({renamed.option} is its former name)",
                                     param_hint=now)
        warnings.warn(f"{renamed.option} is renamed {now}", stacklevel=2)
        out[renamed.new] = out.pop(renamed.old)
    return out
