"""Each setting is written once: one entry of the option table, one flag on every command
that takes it, and its default in the settings' dataclasses alone. Read from the source
(an AST walk of src/pcmapq): no function's default or ``x or N`` fallback copies a setting's
default, and no help text spells a default out as a number."""

from __future__ import annotations

import ast
import re
from collections import defaultdict
from pathlib import Path

import pytest
import typer

from pcmapq.cli import app
from pcmapq.settings.build import default_of
from pcmapq.settings.configs import TRACK_EVERY
from pcmapq.settings.table import OPTIONS

SRC = Path(__file__).resolve().parents[3] / "src" / "pcmapq"
#: Where defaults are defined (the settings) and what is not the pipeline (test data).
DEFINED = ("settings",)
SKIPPED = ("testing",)
#: Settings of a command's own that are not in the table, by parameter name.
BEYOND_TABLE = {"every": {TRACK_EVERY}}
#: A parameter named as a setting that is another setting: ``pcmapq map``'s ``--voxel``, the
#: cell of the map it writes (not ``noref.voxel``), by module.
OTHER_SETTINGS = {("voxel", "cli/map_scans.py"), ("voxel", "mapping/kiss.py"),
                  ("voxel", "mapping/reference.py")}
#: A number said to be a default in words: "default 0.05", "default: 2", "uses 20000".
SPELLED_DEFAULT = re.compile(r"\b(default|uses)\b:?\s*[-+]?\.?\d", re.IGNORECASE)


def table_defaults() -> dict[str, set]:
    """Each setting's default(s), by option name and by its key in its group: numbers and
    words only (a switch, a null and a 0 that turns a step off are no value to copy)."""
    found: dict[str, set] = defaultdict(set)
    for option in OPTIONS:
        for command in option.commands:
            value = default_of(command, option.path)
            if isinstance(value, int | float | str) and not isinstance(value, bool) and value:
                found[option.name].add(value)
                found[option.path.rsplit(".", 1)[-1]].add(value)
    for name, values in BEYOND_TABLE.items():
        found[name] |= values
    return found


def modules(*under: str) -> list[Path]:
    """The package's modules (those under ``under`` only, when given), test data left out."""
    paths = sorted(SRC.rglob("*.py"))
    keep = [p for p in paths if p.relative_to(SRC).parts[0] not in SKIPPED]
    return [p for p in keep if not under or p.relative_to(SRC).parts[0] in under]


def copies(path: Path, defaults: dict[str, set]) -> list[str]:
    """Where ``path`` writes a setting's default again: a parameter's default, or the
    fallback of ``name or N``."""
    where = path.relative_to(SRC).as_posix()
    found = []

    def check(name: str, node: ast.expr | None, line: int) -> None:
        if (isinstance(node, ast.Constant) and not isinstance(node.value, bool)
                and node.value in defaults.get(name, ()) and (name, where) not in OTHER_SETTINGS):
            found.append(f"{where}:{line}: {name} = {node.value!r}")

    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            args = node.args
            positional = [*args.posonlyargs, *args.args]
            defaulted = positional[len(positional) - len(args.defaults):]
            pairs = [*zip(defaulted, args.defaults, strict=True),
                     *zip(args.kwonlyargs, args.kw_defaults, strict=True)]
            for arg, default in pairs:
                check(arg.arg, default, node.lineno)
        elif isinstance(node, ast.BoolOp) and isinstance(node.op, ast.Or):
            first, *rest = node.values
            if isinstance(first, ast.Name):
                for value in rest:
                    check(first.id, value, node.lineno)
    return found


def help_texts(path: Path) -> list[tuple[int, str]]:
    """The literal text of every help in ``path``: a ``help=`` or ``helps=`` argument, and an
    option table entry's help (:class:`~pcmapq.settings.table.Option`'s fourth argument)."""
    texts = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.Call):
            continue
        parts = [k.value for k in node.keywords if k.arg in ("help", "helps")]
        if getattr(node.func, "id", None) == "Option" and len(node.args) > 3:
            parts.append(node.args[3])
        texts += [(part.lineno, text.value) for part in parts for text in ast.walk(part)
                  if isinstance(text, ast.Constant) and isinstance(text.value, str)]
    return texts


def test_no_function_copies_a_settings_default():
    """``match(..., threshold=0.5)``, ``every or 20``: a default written twice drifts; a
    function takes its default from the settings (or from the light module below them that
    holds it)."""
    defaults = table_defaults()
    found = [c for path in modules() if path.relative_to(SRC).parts[0] not in DEFINED
             for c in copies(path, defaults)]
    assert not found, "defaults copied outside pcmapq.settings:\n" + "\n".join(found)


def test_no_help_text_spells_out_a_default():
    """Typer shows each option's default from the table ("[default: 0.5]"); a help that says
    "default 0.05" or "uses 20000" restates it and goes stale. A help that must name another
    setting's value formats it from that setting."""
    found = [f"{path.relative_to(SRC)}:{line}: {text!r}"
             for path in modules("cli", "settings") for line, text in help_texts(path)
             if SPELLED_DEFAULT.search(text)]
    assert not found, "help texts with a default written in:\n" + "\n".join(found)


def test_each_setting_has_one_entry_in_the_table():
    paths = [o.path for o in OPTIONS]
    names = [o.name for o in OPTIONS]
    assert len(set(paths)) == len(paths), sorted(p for p in paths if paths.count(p) > 1)
    assert len(set(names)) == len(names), sorted(n for n in names if names.count(n) > 1)


def test_no_two_flags_of_any_commands_name_one_setting():
    """Every command's visible options that set a setting of the table: one flag per setting
    across all the commands (eval's --noref-radius is inspect's too)."""
    by_name = {o.name: o.path for o in OPTIONS}
    flags: dict[str, set[str]] = defaultdict(set)
    for command in typer.main.get_command(app).commands.values():
        for param in command.params:
            if param.name in by_name and not getattr(param, "hidden", False):
                flags[by_name[param.name]].add(f"{param.opts[0]}")
    assert {p: f for p, f in flags.items() if len(f) > 1} == {}


@pytest.mark.parametrize("option", ["scan_topic"])
def test_an_option_several_commands_share_is_defined_once(option):
    """The scans' topic of eval (--scans), map and track: one definition, one help."""
    commands = typer.main.get_command(app).commands
    helps = {name: p.help for name in ("eval", "map", "track")
             for p in commands[name].params if p.name == option}
    assert len(helps) == 3 and len(set(helps.values())) == 1, helps
