"""An option is one line of the option table: added there, it reaches the command line of every
command that takes it (its flag, default, help and bounds), the settings it builds, the batch
manifest's columns and the ``pcmapq eval`` line a row records, the settings file's checks and
the docs' option tables. The test adds one (``alignment.min_confidence``, which no option sets
today) and looks for it in each."""

from __future__ import annotations

from typing import Any

import pytest
import typer

from pcmapq.batch.manifest import columns, make_row
from pcmapq.cli.options import settings_of, settings_options
from pcmapq.core.errors import InputError
from pcmapq.report.docs_tables import options_table
from pcmapq.settings import AlignmentConfig, Settings
from pcmapq.settings import table as option_table
from pcmapq.settings.build import option_words
from pcmapq.settings.file import read_settings
from pcmapq.settings.table import BATCH, EVAL, FLOAT, INSPECT, TRACK, Option

NEW = Option("min_confidence", "alignment.min_confidence", FLOAT,
             "Refuse a map whose confidence is below this.", 0.0, 1.0,
             commands=(EVAL, BATCH, TRACK))


@pytest.fixture
def added(monkeypatch: pytest.MonkeyPatch) -> Option:
    """The option table with :data:`NEW` as its last line."""
    monkeypatch.setattr(option_table, "OPTIONS", (*option_table.OPTIONS, NEW))
    return NEW


def built_command(name: str) -> typer.main.TyperCommand:
    """A command that takes the settings of ``name`` as every pcmapq command does
    (:func:`settings_options`), built now, from the table as it is."""
    app = typer.Typer()

    @app.command()
    @settings_options(name)
    def run(ctx: typer.Context, **settings_values: Any) -> None:
        """A command with settings only."""

    return typer.main.get_command(app)


@pytest.mark.parametrize("name", [EVAL, TRACK])
def test_a_new_option_reaches_the_command_line_of_its_commands(added, name):
    command = built_command(name)
    param = {p.name: p for p in command.params}[added.name]
    assert param.opts == ["--min-confidence"] and param.default == AlignmentConfig.min_confidence
    assert param.help == added.help and param.show_default
    ctx = command.make_context(name, ["--min-confidence", "0.7"])
    assert settings_of(ctx, name, ctx.params).alignment.min_confidence == 0.7
    with pytest.raises(typer.BadParameter):  # out of [0, 1]: refused
        command.make_context(name, ["--min-confidence", "2"])
    assert added.name not in {p.name for p in built_command(INSPECT).params}


def test_a_new_option_reaches_the_manifest_and_the_rows_command(added, tmp_path):
    assert added.name in columns()
    row = make_row({"map": "m.png", "truth": "t.png", "min_confidence": "0.7"}, tmp_path, "row 1")
    assert row.settings.alignment.min_confidence == 0.7
    assert "--min-confidence 0.7" in row.command({})
    assert option_words({added.name: 0.7}, EVAL) == ["--min-confidence", "0.7"]
    with pytest.raises(InputError, match=r"row 1: min_confidence: expected a finite number "
                                         r"in \[0, 1\]"):
        make_row({"map": "m.png", "truth": "t.png", "min_confidence": "2"}, tmp_path, "row 1")


def test_a_new_option_reaches_the_settings_files_checks(monkeypatch, tmp_path):
    path = tmp_path / "settings.yaml"
    path.write_text("alignment: {min_confidence: 2.0}\n")
    assert read_settings(path).alignment.min_confidence == 2.0  # no option: not checked
    monkeypatch.setattr(option_table, "OPTIONS", (*option_table.OPTIONS, NEW))
    with pytest.raises(InputError, match=r"alignment.min_confidence: expected a number in "
                                         r"\[0, 1\], got 2.0"):
        read_settings(path)
    path.write_text("alignment: {min_confidence: 0.7}\n")
    assert read_settings(path, Settings()).alignment.min_confidence == 0.7


def test_a_new_option_reaches_the_docs_option_tables(added):
    row = ("| `--min-confidence P` | `alignment.min_confidence` | `0.5` | Refuse a map whose "
           "confidence is below this. |")
    assert row in options_table(EVAL).splitlines()
    assert row in options_table(TRACK).splitlines()
    assert row not in options_table(INSPECT).splitlines()
