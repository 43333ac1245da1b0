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
])
def test_a_bad_settings_file_is_one_line_naming_the_file_and_key(text, message, tmp_path):
    path = tmp_path / "settings.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=message) as err:
        read_settings(path, Settings())
    assert str(err.value).startswith(f"{path}: ")
    got = CliRunner().invoke(app, ["eval", "m.png", "t.png", "--config", str(path)])
    assert got.exit_code == 2 and got.stderr.count("\n") == 1 and str(path) in got.stderr
