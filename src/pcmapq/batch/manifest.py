"""A batch's rows: read from a CSV or YAML manifest, or one per map of a glob. Each row's
options are ``pcmapq eval``'s, by name (``threshold``, ``map_resolution`` ...), turned into
:class:`~pcmapq.settings.Settings` by the same parsers as eval's, and into the ``pcmapq eval``
command line that makes the same result. A bad manifest is one InputError (exit 2) naming
the file, the row and the problem."""

from __future__ import annotations

import csv
import glob
import math
import os
import shlex
import warnings
from dataclasses import dataclass
from pathlib import Path

import yaml

from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.settings import Settings
from pcmapq.settings.build import build, option_words
from pcmapq.settings.file import read_settings
from pcmapq.settings.renamed import renamed_of
from pcmapq.settings.table import (
    BATCH,
    EVAL,
    INT,
    SWITCH,
    TEXT,
    Option,
    OptionError,
    options_of,
)

#: Names a row cannot take: the batch's own table and figure are written beside the rows.
RESERVED = ("table", "figure")
MANIFEST_SUFFIXES = (".csv", ".yaml", ".yml")
#: The columns of a row that are no option.
ROW_COLUMNS = ("name", "map", "truth")


def row_options() -> dict[str, Option]:
    """The per-row options: eval's settings options, by name (the option table's)."""
    return {o.name: o for o in options_of(BATCH)}


def columns() -> tuple[str, ...]:
    """Every column a manifest may have."""
    return (*ROW_COLUMNS, *row_options())


@dataclass(frozen=True)
class Row:
    """One evaluation: its name (the stem of its outputs), map and truth (absolute paths, as
    the workers read them), settings, and its options as given (parsed values, by column)."""

    name: str
    map: Path
    truth: Path
    settings: Settings
    options: dict[str, object]
    config: Path | None = None

    def command(self, outputs: dict[str, Path]) -> str:
        """The ``pcmapq eval`` command line that makes this row's result and writes
        ``outputs`` (``{"--json": path, ...}``), as eval records its own (defaults left out):
        its outputs, the batch's settings file, then the row's options."""
        words = ["pcmapq", "eval", str(self.map), str(self.truth)]
        for option in ("--json", "--plot", "--report"):
            if option in outputs:
                words += [option, str(outputs[option])]
        words += [] if self.config is None else ["--config", str(self.config)]
        words += option_words(self.options, EVAL)
        return shlex.join(words)


def read_rows(manifest: Path, defaults: dict[str, object],
              config: Path | None = None) -> list[Row]:
    """The rows of a CSV or YAML manifest. Relative paths in it are relative to its folder;
    ``defaults`` (column -> text, e.g. from ``--set``) fill the cells a row leaves empty;
    ``config``: a settings file every row starts from."""
    suffix = manifest.suffix.lower()
    if suffix not in MANIFEST_SUFFIXES:
        raise InputError(f"{manifest}: a manifest is .csv, .yaml or .yml")
    try:
        text = manifest.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{manifest}: cannot read: {getattr(exc, 'strerror', None) or exc}"
                         ) from None
    cells = _csv_cells(manifest, text) if suffix == ".csv" else _yaml_cells(manifest, text)
    if not cells:
        raise InputError(f"{manifest}: no rows")
    _warn_renamed([k for row in cells for k in row], str(manifest))
    base = Path(os.path.abspath(manifest.parent))
    start = _start(config)
    rows = [make_row({**defaults, **row}, base, f"{manifest}: row {i}", start)
            for i, row in enumerate(cells, 1)]
    check_names(rows, str(manifest))
    return rows


def glob_rows(patterns: list[str], truth: Path, defaults: dict[str, object],
              config: Path | None = None) -> list[Row]:
    """One row per map matching ``patterns`` (globs or paths, relative to the current folder,
    sorted, each map once), all against ``truth``; a row's name is its map's stem."""
    maps: list[str] = []
    for pattern in patterns:
        found = sorted(glob.glob(pattern)) if glob.has_magic(pattern) else [pattern]
        if not found:
            raise InputError(f"{pattern}: matches no file")
        maps += [m for m in found if m not in maps]
    here = Path(os.path.abspath("."))
    start = _start(config)
    rows = [make_row({**defaults, "map": m, "truth": str(truth)}, here, m, start)
            for m in maps]
    check_names(rows, " ".join(patterns))
    return rows


def parse_assignments(pairs: list[str]) -> dict[str, object]:
    """``--set KEY=VALUE`` options as defaults of every row (keys as manifest columns but
    name and map; a truth path is the current folder's)."""
    values: dict[str, object] = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        _warn_renamed([key], "--set")
        key = _column(key, f"--set {pair}")
        if not sep or key in ("name", "map"):
            raise InputError(f"--set {pair}: expected KEY=VALUE with KEY an option of a row "
                             f"({', '.join(c for c in columns() if c not in ('name', 'map'))})")
        values[key] = os.path.abspath(Path(value).expanduser()) \
            if key == "truth" and value.strip() else value
    return values


def make_row(cells: dict[str, object], base: Path, where: str,
             start: tuple[Path, Settings] | None = None) -> Row:
    """A row from its cells (column -> text or YAML value; None or '' is unset); paths
    relative to ``base``; errors name ``where``; ``start``: a settings file and its settings,
    which the row's options override."""
    given = {_column(k, where): _text(v, where, k) for k, v in cells.items()}
    given = {k: v for k, v in given.items() if v != ""}
    for required in ("map", "truth"):
        if required not in given:
            raise InputError(f"{where}: no '{required}'")
    options = row_options()
    values = {k: _value(options[k], v, where) for k, v in given.items() if k in options}
    map_path = Path(os.path.abspath(base / Path(given["map"]).expanduser()))
    name = given.get("name", map_path.stem)
    try:
        return Row(name, map_path,
                   Path(os.path.abspath(base / Path(given["truth"]).expanduser())),
                   build(values, EVAL, None if start is None else start[1]), values,
                   None if start is None else start[0])
    except OptionError as exc:
        column = exc.option.lstrip("-").replace("-", "_")
        raise InputError(f"{where}: {column}: {exc.message}") from None
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _start(config: Path | None) -> tuple[Path, Settings] | None:
    """A settings file (absolute, as the workers read it) and its settings, or None."""
    if config is None:
        return None
    path = Path(os.path.abspath(config))
    return path, read_settings(path, Settings())


def check_names(rows: list[Row], where: str) -> None:
    """Refuse a name that is not a plain file stem, reserved, or given to two rows."""
    seen: dict[str, int] = {}
    for i, row in enumerate(rows, 1):
        name = row.name
        if not name or name.startswith(".") or "/" in name or "\\" in name or \
                any(ord(c) < 32 for c in name):
            raise InputError(f"{where}: row {i}: name {name!r}: not a plain file name")
        if name.lower() in RESERVED:
            raise InputError(f"{where}: row {i}: name {name!r} is reserved for the batch's "
                             "table and figure; give another 'name'")
        if name in seen:
            raise InputError(f"{where}: row {i}: name {name!r} is also row {seen[name]}'s; "
                             "give each row its own 'name'")
        seen[name] = i


def _csv_cells(manifest: Path, text: str) -> list[dict[str, object]]:
    """A CSV manifest's rows as cells by column (a header line first; '#' lines skipped)."""
    lines = [line for line in text.splitlines() if not line.lstrip().startswith("#")]
    reader = csv.DictReader(lines, skipinitialspace=True, restkey="\0extra")
    if not reader.fieldnames:
        raise InputError(f"{manifest}: no header line (name,map,truth,... columns)")
    rows = []
    for i, row in enumerate(reader, 1):
        if "\0extra" in row:
            raise InputError(f"{manifest}: row {i}: more cells than the header's "
                             f"{count(len(reader.fieldnames), 'column')}")
        rows.append({k.strip(): ("" if v is None else v.strip()) for k, v in row.items()})
    return [row for row in rows if any(row.values())]


def _yaml_cells(manifest: Path, text: str) -> list[dict[str, object]]:
    """A YAML manifest's rows: a list of mappings, or ``{defaults: {...}, rows: [...]}``."""
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise InputError(f"{manifest}: not YAML: {' '.join(str(exc).split())}") from None
    defaults: dict = {}
    if isinstance(doc, dict) and "rows" in doc:
        extra = set(doc) - {"rows", "defaults"}
        if extra:
            raise InputError(f"{manifest}: unknown key(s) {sorted(map(str, extra))}; a "
                             "manifest has 'rows' and optional 'defaults'")
        defaults, doc = doc.get("defaults") or {}, doc["rows"]
        if not isinstance(defaults, dict):
            raise InputError(f"{manifest}: 'defaults' is not a mapping of options")
    if not isinstance(doc, list):
        raise InputError(f"{manifest}: expected a list of rows (or 'rows:' and 'defaults:')")
    for i, row in enumerate(doc, 1):
        if not isinstance(row, dict):
            raise InputError(f"{manifest}: row {i}: not a mapping of columns (map: ..., "
                             "truth: ...)")
    return [{**defaults, **row} for row in doc]


def _name(key: object) -> str:
    """A column as named (``map-resolution`` and ``map_resolution`` alike)."""
    return str(key).strip().lower().replace("-", "_")


def _column(key: object, where: str) -> str:
    """A column's name, a former one read as its option's (see :func:`_warn_renamed`);
    refuse others."""
    name = _name(key)
    name = {r.old: r.new for r in renamed_of(BATCH)}.get(name, name)
    if name not in columns():
        raise InputError(f"{where}: unknown column {str(key)!r}; columns: "
                         f"{', '.join(columns())}")
    return name


def _warn_renamed(keys: list[object], where: str) -> None:
    """One warning for each former option name among ``keys`` (a manifest's columns)."""
    given = {_name(k) for k in keys}
    for renamed in renamed_of(BATCH):
        if renamed.old in given:
            warnings.warn(f"{where}: column {renamed.old} is renamed {renamed.new}",
                          stacklevel=2)


def _text(value: object, where: str, column: object) -> str:
    """A cell as text: YAML numbers and booleans as written, a list comma-separated."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        return ",".join(_text(v, where, column) for v in value)
    if isinstance(value, dict):
        raise InputError(f"{where}: {column}: expected a value, got a mapping")
    return str(value).strip()


TRUE, FALSE = ("true", "yes", "1", "on"), ("false", "no", "0", "off")


def _value(option: Option, text: str, where: str) -> object:
    """A cell's text as its option's type, within its bounds."""
    column = option.name
    if option.kind == SWITCH:
        if text.lower() not in TRUE + FALSE:
            raise InputError(f"{where}: {column}: expected true or false, got {text!r}")
        return text.lower() in TRUE
    if option.kind == TEXT:
        return text
    try:
        number = int(text) if option.kind == INT else float(text)
    except ValueError:
        number = math.nan
    if not (math.isfinite(number) and option.lo <= number <= option.hi):
        kind = "an integer" if option.kind == INT else "a finite number"
        raise InputError(f"{where}: {column}: expected {kind}{option.bounds}, got {text!r}")
    return number
