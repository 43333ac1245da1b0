"""The option table and the table of figures as the docs show them: one markdown table per
command (option, setting path, default, meaning) between ``<!-- options: COMMAND -->`` and
``<!-- /options -->`` in docs/commands/*.md, and every figure's names between
``<!-- figures -->`` and ``<!-- /figures -->`` in docs/ci.md (``python tools/options_doc.py``
writes them)."""

from __future__ import annotations

import re

from pcmapq.results import figures as table
from pcmapq.results.figures import ALIASES, AT_TAU_COLUMN, MEAN_PRECISION, TAU_FIELDS
from pcmapq.settings.build import base_settings, get_path
from pcmapq.settings.renamed import renamed_of
from pcmapq.settings.table import FLOAT, INT, SWITCH, Option, option_named, options_of

BLOCK = re.compile(r"(<!-- options: (\w+) -->\n).*?(<!-- /options -->)", re.S)
FIGURE_BLOCK = re.compile(r"(<!-- figures -->\n).*?(<!-- /figures -->)", re.S)


def options_table(command: str) -> str:
    """The settings options of ``command`` as a markdown table, then the former names it
    still reads (:data:`~pcmapq.settings.renamed.RENAMED`)."""
    rows = ["| option | setting | default | meaning |", "| --- | --- | --- | --- |"]
    defaults = base_settings(command)
    for option in options_of(command):
        rows.append(f"| {_typed(option)} | `{option.path}` | "
                    f"{_default(option.show(get_path(defaults, option.path)))} | "
                    f"{option.help_for(command).replace('|', '/')} |")
    former = [f"`{r.option}` (`{option_named(r.new).option}`)" for r in renamed_of(command)]
    if former:
        rows += ["", "Former names, still read with a warning: " + ", ".join(former) + "."]
    return "\n".join(rows) + "\n"


def update(page: str) -> str:
    """``page`` with each options block made from the option table as it is, and its figures
    block (docs/ci.md) from the table of figures."""
    page = BLOCK.sub(lambda m: m[1] + options_table(m[2]) + m[3], page)
    return FIGURE_BLOCK.sub(lambda m: m[1] + figures_table() + m[2], page)


def _typed(option: Option) -> str:
    if option.kind == SWITCH:
        return " / ".join(f"`{f}`" for f in (option.flag or "").split("/"))
    value = (option.metavar or ("N" if option.kind == INT else "P" if option.hi == 1.0 else
                                "M" if option.kind == FLOAT else "TEXT"))
    return f"`{option.option} {value.strip('<>').replace('|', '/')}`"


def _default(value: object) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "on" if value else "off"
    return f"`{value:g}`" if isinstance(value, float) else f"`{value}`"


def figures_table() -> str:
    """Every named figure as a markdown table (name, JSON path, table column), as
    docs/ci.md lists the gates' keys."""
    rows = ["| name (gate key) | JSON path | table column | header |",
            "| --- | --- | --- | --- |"]
    rows += [f"| `{f.name}` | `{'.'.join(f.path)}` | "
             f"{f'`{f.column_name}`' if f.column else '-'} | {f.header} |"
             for f in table.FIGURES if f.number]
    rows += [f"| `{name}@TAU`, `{name}_3d@TAU` | `distances.f_score.<i>.{key}` | "
             f"`{AT_TAU_COLUMN.format(name=name, tau=0.05).replace('0.05', 'TAU')}` | "
             f"{name.replace('_', ' ')} at TAU |" for name, key in TAU_FIELDS.items()]
    rows.append(f"| - | mean of `detectors.<name>.precision`, rooms aside | "
                f"`{MEAN_PRECISION}` (track) | precision |")
    rows += [f"| `{alias}` (other name of `{name}`) | | | |" for alias, name in ALIASES.items()]
    return "\n".join(rows) + "\n"
