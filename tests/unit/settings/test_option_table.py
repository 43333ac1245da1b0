"""The option table (pcmapq.settings.table) is the one list of options: every option reaches
the typer commands, the batch manifest, the settings builder and the settings file alike, and
a settings file (--config) is overridden by the options given on the command line."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
import typer

from pcmapq.batch.manifest import columns, make_row
from pcmapq.cli import app
from pcmapq.cli.options import settings_of
from pcmapq.settings import Settings
from pcmapq.settings.build import base_settings, build, get_path, option_words
from pcmapq.settings.file import dump_settings, read_settings
from pcmapq.settings.table import (
    BATCH,
    EVAL,
    FLOAT,
    INT,
    OPTIONS,
    SWITCH,
    TEXT,
    Option,
    options_of,
)
from testkit.paths import REPO

#: A value other than the default for each text option, as typed.
TEXTS = {"scale": "auto", "map_resolution": "0.1", "map_crop": "-5,-5,5,5",
         "truth_crop": "-6,-6,6,6", "init": "1,2,3", "detectors": "sift", "tau": "0.3,0.4",
         "footprint": "walls", "map_topic": "/slam/map", "truth_topic": "/truth_map",
         "init_3d": "0,-1,0,1,1,0,0,2,0,0,1,0.5,0,0,0,1"}


def sample(option: Option, command: str) -> object:
    """A value of ``option`` unlike its default, as the command line gives it."""
    default = option.show(get_path(base_settings(command), option.path))
    if option.kind == TEXT:
        return TEXTS[option.name]
    if option.kind == SWITCH:
        return not default
    lo = option.lo if math.isfinite(option.lo) else 0.0
    value = min(lo + 0.25, option.hi) if option.kind == FLOAT else int(lo) + 2
    return value if value != default else value + (0.125 if option.kind == FLOAT else 1)


def command(name: str) -> typer.main.TyperCommand:
    return typer.main.get_command(app).commands[name]


@pytest.mark.parametrize("name", [EVAL, "track", "inspect"])
def test_each_commands_options_are_the_tables(name):
    params = {p.name for p in command(name).params}
    assert {o.name for o in options_of(name)} <= params
    assert "config" in params


@pytest.mark.parametrize("option", options_of(EVAL), ids=lambda o: o.name)
def test_an_option_on_the_command_line_a_manifest_and_a_file_gives_one_setting(option, tmp_path):
    value = sample(option, EVAL)
    built = build({option.name: value}, EVAL)
    assert get_path(built, option.path) != get_path(Settings(), option.path) or \
        option.also(option.read(value))
    words = option_words({option.name: value}, EVAL)
    ctx = command(EVAL).make_context("eval", ["m.png", "t.png", *words])
    assert settings_of(ctx, EVAL, ctx.params) == built  # the command line rebuilt, parsed
    assert option.name in columns()
    row = make_row({"map": "m.png", "truth": "t.png", option.name: str(value).lower()
                    if isinstance(value, bool) else str(value)}, tmp_path, "row 1")
    assert row.settings == built
    path = tmp_path / "settings.yaml"
    path.write_text(dump_settings(built))
    assert read_settings(path, Settings()) == built


def test_the_command_line_overrides_the_file_which_overrides_the_defaults(tmp_path):
    path = tmp_path / "settings.yaml"
    path.write_text("matching:\n  threshold: 0.3\n  detectors: [harris, sift]\n"
                    "footprint: {margin: 0.6}\n")
    cmd = command(EVAL)
    ctx = cmd.make_context("eval", ["m.png", "t.png", "--config", str(path)])
    from_file = settings_of(ctx, EVAL, ctx.params)
    assert from_file.matching.threshold == 0.3 and from_file.footprint.margin == 0.6
    assert from_file.matching.detectors == ("harris", "sift")
    assert from_file.raster == Settings().raster
    ctx = cmd.make_context("eval", ["m.png", "t.png", "--config", str(path), "--threshold",
                                    "0.4"])
    both = settings_of(ctx, EVAL, ctx.params)
    assert both == replace(from_file, matching=replace(from_file.matching, threshold=0.4))


def test_every_option_has_a_setting_and_a_sample():
    for option in OPTIONS:
        get_path(base_settings(option.commands[0]), option.path)  # the path exists
        assert option.kind in (FLOAT, INT, TEXT, SWITCH)
        if option.kind == TEXT:
            assert option.name in TEXTS
    assert {o.name for o in options_of(BATCH)} == {o.name for o in options_of(EVAL)}


def test_inspect_takes_its_noref_settings_from_the_table_with_no_voxel_by_default():
    ctx = command("inspect").make_context("inspect", ["m.ply", "--noref-radius", "0.2"])
    settings = settings_of(ctx, "inspect", ctx.params)
    assert settings.noref.radius == 0.2 and settings.noref.voxel == 0.0


def test_the_command_pages_list_the_tables_options():
    """docs/commands/*.md show each command's settings options as the table has them
    (python tools/options_doc.py writes them)."""
    from pcmapq.report.docs_tables import BLOCK, FIGURE_BLOCK, update

    docs = REPO / "docs"
    pages = [*sorted((docs / "commands").glob("*.md")), docs / "ci.md"]
    shown = {m[2] for page in pages for m in BLOCK.finditer(page.read_text())}
    assert shown == {EVAL, BATCH, "track", "inspect"}
    assert FIGURE_BLOCK.search((docs / "ci.md").read_text())
    for page in pages:
        assert update(page.read_text()) == page.read_text(), \
            f"{page.name}: run python tools/options_doc.py"


def test_settings_recorded_without_the_3d_map_group_read_back_with_its_defaults():
    """A result of no two 3D clouds records no ``map_3d`` group (nor did results before it)."""
    doc = Settings().to_dict()
    del doc["map_3d"]
    assert Settings.from_dict(doc) == Settings()
