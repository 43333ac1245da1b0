"""Settings files on the command line: `pcmapq config --dump` writes the defaults as a file that
reads back as them; a bad settings file is one line naming the file and the key."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.core.errors import InputError
from pcmapq.settings import Settings
from pcmapq.settings.file import read_settings

#: Both stop at their parsing: milliseconds.
pytestmark = pytest.mark.unit


def test_the_dumped_defaults_read_back_as_the_defaults(tmp_path):
    got = CliRunner().invoke(app, ["config", "--dump"])
    assert got.exit_code == 0
    path = tmp_path / "settings.yaml"
    path.write_text(got.stdout)
    assert read_settings(path, Settings()) == Settings()


@pytest.mark.parametrize(("text", "message"), [
    ("matching:\n  treshold: 0.3\n", "unknown setting 'matching.treshold' .did you mean "
                                     "'matching.threshold'"),
    ("matching:\n  threshold: -1\n", r"matching.threshold: expected a number >= 1e-06"),
    ("matching:\n  threshold: fast\n", "matching.threshold: expected a number"),
    ("distances:\n  taus: [0.1, -2]\n", "distances.taus: expected positive finite"),
    ("matching:\n  detectors: [harris, orb]\n", r"unknown detector\(s\) \['orb'\]"),
    ("alignment:\n  enabled: false\n  scale: true\n", "cannot go together"),
    ("- a list\n", "expected a mapping"),
    ("{ not: yaml: at all\n", "not YAML"),
    ("alignment:\n  scale: sometimes\n", "alignment.scale: expected 'fixed' or 'auto', got "
                                         "'sometimes'"),
])
def test_a_bad_settings_file_is_one_line_naming_the_file_and_key(text, message, tmp_path):
    path = tmp_path / "settings.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=message) as err:
        read_settings(path, Settings())
    assert str(err.value).startswith(f"{path}: ")
    got = CliRunner().invoke(app, ["eval", "m.png", "t.png", "--config", str(path)])
    assert got.exit_code == 2 and got.stderr.count("\n") == 1 and str(path) in got.stderr


@pytest.mark.parametrize(("text", "changed"), [
    ("alignment: {scale: auto}\n", {"alignment.scale": True}),
    ("alignment: {scale: fixed}\n", {}),
    ("map: {resolution: auto}\n", {"alignment.scale": True}),
    ("map: {resolution: 0.1}\n", {"map.resolution": 0.1}),
    ("matching: {detectors: 'harris,hough'}\n", {"matching.detectors": ("harris", "hough")}),
    ("alignment: {init: '1,2,90'}\n", {"alignment.init.x_m": 1.0, "alignment.init.yaw_deg": 90.0}),
])
def test_a_settings_file_takes_the_words_the_options_take(text, changed, tmp_path):
    """The option table's words (``--scale auto``, ``--map-resolution auto``, ``--init x,y,yaw``)
    read in a settings file as on the command line."""
    path = tmp_path / "settings.yaml"
    path.write_text(text)
    doc = read_settings(path).to_dict()
    default = Settings().to_dict()
    for key, value in changed.items():
        here, there = doc, default
        for step in key.split("."):
            here, there = here[step], (there or {}).get(step)
        assert (tuple(here) if isinstance(here, list) else here) == value != there
    if not changed:
        assert doc == default


def test_config_with_a_file_alone_checks_it(tmp_path):
    """``pcmapq config --config FILE``: exit 0, a comment naming the file, then the settings
    it changes as read; a bad file: one line naming it, exit 2."""
    good = tmp_path / "tuned.yaml"
    good.write_text("matching: {threshold: 0.3}\nalignment: {scale: auto}\n")
    got = CliRunner().invoke(app, ["config", "--config", str(good)])
    assert got.exit_code == 0, got.stderr
    assert got.stdout == (f"# {good}: read; 2 settings changed from the defaults\n"
                          "alignment:\n  scale: true\nmatching:\n  threshold: 0.3\n")
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    got = CliRunner().invoke(app, ["config", "--config", str(empty)])
    assert (got.exit_code, got.stdout) == (0, f"# {empty}: read; every setting at its default\n")
    bad = tmp_path / "bad.yaml"
    bad.write_text("matching: {treshold: 0.3}\n")
    got = CliRunner().invoke(app, ["config", "--config", str(bad)])
    assert got.exit_code == 2 and got.stderr.count("\n") == 1
    assert got.stderr.startswith(f"pcmapq: error: {bad}: unknown setting 'matching.treshold'")
    got = CliRunner().invoke(app, ["config", "--config", str(tmp_path / "absent.yaml")])
    assert got.exit_code == 2 and got.stderr.count("\n") == 1 and "absent.yaml" in got.stderr
    got = CliRunner().invoke(app, ["config"])
    assert got.exit_code == 2 and "--config FILE" in got.stderr
