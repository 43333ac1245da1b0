"""An option's former name (:data:`pcmapq.settings.renamed.RENAMED`) is still read where it was
taken, with one warning naming the option now, and recorded under its name: a command's hidden
option, a batch manifest's column."""

from __future__ import annotations

import warnings

import pytest
import typer

from pcmapq.batch.manifest import parse_assignments, read_rows
from pcmapq.cli import app
from pcmapq.cli.options import command_line, settings_of
from pcmapq.settings import renamed as renamed_names
from pcmapq.settings.renamed import RENAMED, Renamed
from pcmapq.settings.table import (
    BATCH,
    INSPECT,
    SWITCH,
    option_named,
    options_of,
)


def command(name: str) -> typer.main.TyperCommand:
    return typer.main.get_command(app).commands[name]


def test_every_former_name_names_an_option_of_its_commands_and_nothing_else():
    names = {o.name for o in options_of()}
    for renamed in RENAMED:
        option = option_named(renamed.new)
        assert option.kind != SWITCH and renamed.old not in names
        for name in renamed.commands:
            assert name in option.commands
            own = {p.name for p in command(name).params} - names - {r.old for r in RENAMED}
            assert renamed.old not in own


@pytest.mark.parametrize("renamed", [r for r in RENAMED if INSPECT in r.commands],
                         ids=lambda r: r.old)
def test_inspect_reads_a_former_name_as_its_option_with_one_warning(renamed):
    option = option_named(renamed.new)
    value = {"map_crop": "-5,-5,5,5", "map_topic": "/slam/map"}.get(renamed.new, "7")
    ctx = command(INSPECT).make_context(INSPECT, ["m.ply", renamed.option, value])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = settings_of(ctx, INSPECT, ctx.params)
    assert [str(w.message) for w in caught] == [f"{renamed.option} is renamed {option.option}"]
    line = command_line(ctx)
    assert line.startswith(f"pcmapq inspect m.ply {option.option} ")
    ctx = command(INSPECT).make_context(INSPECT, ["m.ply", option.option, value])
    assert settings_of(ctx, INSPECT, ctx.params) == old and command_line(ctx) == line


def test_a_former_name_beside_its_option_is_a_usage_error():
    ctx = command(INSPECT).make_context(INSPECT, ["m.ply", "--radius", "0.2", "--noref-radius",
                                                  "0.3"])
    with pytest.raises(typer.BadParameter, match=r"give it once \(--radius is its former"):
        settings_of(ctx, INSPECT, ctx.params)


def test_the_help_shows_the_options_and_not_their_former_names():
    from typer.testing import CliRunner

    shown = CliRunner().invoke(app, ["inspect", "--help"]).stdout
    assert "--noref-radius" in shown and "--map-crop" in shown
    assert "--radius" not in shown.replace("--noref-radius", "")
    assert "--crop" not in shown.replace("--map-crop", "")


def test_a_manifest_column_renamed_is_read_with_one_warning(monkeypatch, tmp_path):
    """batch has no former name yet: one is added, and read through the same list."""
    monkeypatch.setattr(renamed_names, "RENAMED",
                        (*RENAMED, Renamed("match_distance", "threshold", (BATCH,))))
    manifest = tmp_path / "rows.csv"
    manifest.write_text("map,truth,match_distance\na.png,t.png,0.3\nb.png,t.png,0.4\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = read_rows(manifest, {})
        assert parse_assignments(["match-distance=0.2"]) == {"threshold": "0.2"}
    assert [str(w.message) for w in caught] == [
        f"{manifest}: column match_distance is renamed threshold",
        "--set: column match_distance is renamed threshold"]
    assert [r.settings.matching.threshold for r in rows] == [0.3, 0.4]
    assert "--threshold 0.3" in rows[0].command({})
