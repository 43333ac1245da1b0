"""The formats a user is told of are the formats the loaders read: every suffix of the loaders'
registry (:mod:`pcmapq.io.formats`) is read by ``load_map`` and named in the help of the commands
that take a map and in the unsupported-format message; a folder of scans given as a map names
``--scans``; a missing resolution names the option the command has; the install guide names
only packages pcmapq depends on."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.core.errors import InputError
from pcmapq.io import load_map
from pcmapq.io.formats import MAP_SUFFIXES, SCAN_SUFFIXES
from testkit.paths import REPO, SAMPLE

#: Each stops at its parsing or at its first input: milliseconds.
pytestmark = pytest.mark.unit


def help_of(command: str) -> str:
    """``pcmapq COMMAND --help`` with its lines joined (a list of formats may wrap)."""
    got = CliRunner().invoke(app, [command, "--help"], terminal_width=200)
    assert got.exit_code == 0, got.output
    return " ".join(got.output.split())


def named(suffix: str, text: str) -> bool:
    """Whether ``text`` names ``suffix`` as a whole (``.log`` inside ``.log.gz`` is not)."""
    return re.search(re.escape(suffix) + r"(?![\w.])", text) is not None


@pytest.mark.parametrize("suffix", MAP_SUFFIXES)
def test_every_registered_suffix_is_read_by_a_loader(suffix, tmp_path):
    """A file of each suffix reaches its loader: refused for its content, never for its
    suffix."""
    path = tmp_path / f"junk{suffix}"
    path.write_bytes(b"not a map\n")
    with pytest.raises(InputError) as err:
        load_map(path)
    assert "unsupported format" not in str(err.value), err.value


@pytest.mark.parametrize("command", ["eval", "inspect", "info"])
def test_the_help_names_every_format_the_loaders_read(command):
    text = help_of(command)
    assert [s for s in MAP_SUFFIXES if not named(s, text)] == []
    assert "ROS 2 bag folder" in text


def test_the_scans_help_names_every_scan_format():
    for command in ("eval", "inspect", "map", "track"):
        text = help_of(command)
        assert [s for s in SCAN_SUFFIXES if not named(s, text)] == [], command


def test_the_unsupported_format_message_names_every_format(tmp_path):
    path = tmp_path / "map.abc"
    path.write_text("1 2 3\n")
    got = CliRunner().invoke(app, ["info", str(path)])
    assert got.exit_code == 2 and got.stderr.count("\n") == 1
    assert f"{path}: unsupported format '.abc'" in got.stderr
    assert [s for s in MAP_SUFFIXES if not named(s, got.stderr)] == []


def test_a_folder_of_scans_given_as_the_map_names_scans(tmp_path):
    scans = tmp_path / "velodyne"
    scans.mkdir()
    for k in range(3):
        (scans / f"{k:06d}.bin").write_bytes(bytes(32))
    got = CliRunner().invoke(app, ["eval", str(tmp_path), str(SAMPLE / "truth.yaml")])
    assert got.exit_code == 2 and got.stderr.count("\n") == 1, got.stderr
    assert (f"pcmapq: error: {tmp_path}: a folder of 3 scan files, not a map: give it as "
            "--scans FOLDER") in got.stderr
    other = tmp_path / "empty"
    other.mkdir()
    got = CliRunner().invoke(app, ["inspect", str(other)])
    assert got.exit_code == 2 and "a folder, not a map file" in got.stderr


@pytest.mark.parametrize(("args", "option"), [
    (["inspect", "{png}"], "--map-resolution"),
    (["eval", "{png}", str(SAMPLE / "truth.yaml")], "--map-resolution"),
    (["eval", str(SAMPLE / "truth.yaml"), "{png}"], "--truth-resolution"),
])
def test_an_image_without_resolution_names_the_option_the_command_has(args, option, tmp_path):
    png = tmp_path / "lonely.png"
    png.write_bytes((SAMPLE / "truth.png").read_bytes())
    args = [a.format(png=png) for a in args]
    got = CliRunner().invoke(app, args)
    assert got.exit_code == 2 and got.stderr.count("\n") == 1, got.stderr
    assert f"no resolution: give {option} or a YAML beside it" in got.stderr
    assert option in help_of(args[0])


def dependencies() -> set[str]:
    """The names of pcmapq's dependencies and their extras, optional ones too."""
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    specs = project["dependencies"] + [s for group in project["optional-dependencies"].values()
                                       for s in group]
    names = set()
    for spec in specs:
        name, _, extras = re.match(r"([\w.-]+)(\[([\w,.-]+)\])?", spec).groups()
        names |= {name.lower(), *(extras or "").split(",")}
    return names - {""}


def test_the_install_guide_names_only_packages_pcmapq_depends_on():
    """Every package the install section names (in backticks) is a dependency or one's extra;
    the system library it names is said to be one."""
    page = (REPO / "docs" / "getting-started.md").read_text()
    install = page.split("## Install", 1)[1].split("\n## ", 1)[0]
    words = set(re.findall(r"`([a-z][\w.-]*)`", install))
    system = {w for w in words if f"system library `{w}`" in " ".join(install.split())}
    assert words - system - dependencies() == set()
    assert system == {"libusb-1.0-0"}


def test_the_formats_page_names_every_format():
    text = (Path(REPO) / "docs" / "formats.md").read_text()
    assert [s for s in MAP_SUFFIXES if not named(s, text)] == []


def test_info_counts_one_point_in_the_singular(tmp_path):
    path = tmp_path / "one.xyz"
    path.write_text("1 2 0\n")
    got = CliRunner().invoke(app, ["info", str(path)])
    assert got.exit_code == 0, got.stderr
    assert got.stdout.startswith(f"{path}: 1 point (")
