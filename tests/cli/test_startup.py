"""`pcmapq --help` and `--version` answer without loading the pipeline: the same output as the
whole application, and none of the heavy libraries imported (they took 1.9 s and 360 MB
before any work)."""

from __future__ import annotations

import subprocess
import sys

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.cli.base import listing_app
from pcmapq.testing.paths import SAMPLE

#: Libraries the pipeline needs and a listing must not import.
HEAVY = ("open3d", "cv2", "kiss_icp", "numpy", "scipy", "skimage", "matplotlib")


@pytest.mark.unit
@pytest.mark.parametrize("args", [["--help"], ["--version"], []], ids=["help", "version", "none"])
def test_the_listing_says_what_the_whole_application_says(args):
    whole = CliRunner().invoke(app, args, prog_name="pcmapq")
    listing = CliRunner().invoke(listing_app(), args, prog_name="pcmapq")
    assert (listing.exit_code, listing.output) == (whole.exit_code, whole.output)
    assert "pcmapq" in listing.output


@pytest.mark.parametrize("flag", ["--help", "--version"])
def test_help_and_version_import_no_heavy_library(flag):
    code = (f"import sys; from pcmapq.cli import main; sys.argv = ['pcmapq', {flag!r}]\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\n"
            f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))")
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert got.returncode == 0, got.stderr
    assert got.stdout.strip().splitlines()[-1] == "[]", got.stdout


def test_a_command_still_gets_the_whole_application():
    got = subprocess.run([sys.executable, "-m", "pcmapq", "eval", "--help"], capture_output=True,
                         text=True, timeout=120)
    assert got.returncode == 0 and "--map-crop" in got.stdout, got.stderr


@pytest.mark.unit
def test_help_offers_what_each_command_does():
    """eval's --footprint does not offer 'seen' (only track has the scans it needs), --plot
    names the formats its extension picks, and eval's gates speak of one result, batch's of
    rows."""
    text = CliRunner().invoke(app, ["eval", "--help"], terminal_width=200).output
    footprint = next(line for line in text.splitlines() if "--footprint" in line)
    assert "seen" not in footprint and "walls" in footprint
    assert "SVG" in text and "PDF" in text
    assert "row" not in text.split("--fail-under")[1].split("--fail-over")[0]
    rows = CliRunner().invoke(app, ["batch", "--help"], terminal_width=200).output
    assert "any row" in rows.split("--fail-under")[1]


def test_dev_null_discards_an_output(tmp_path):
    """`--json /dev/null` (and any output option) discards, as Unix tools do: exit 0, no
    "wrote" line, and /dev/null is still the device."""
    import os
    import stat

    sample = SAMPLE
    got = CliRunner().invoke(app, ["eval", str(sample / "scan.ply"), str(sample / "truth.png"),
                                   "--json", os.devnull, "--plot", os.devnull, "--quiet"])
    assert got.exit_code == 0, got.stderr
    assert "wrote" not in got.stderr
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)
    got = CliRunner().invoke(app, ["inspect", str(sample / "truth.yaml"), "--json", os.devnull])
    assert got.exit_code == 0 and "wrote" not in got.stderr, got.stderr


def test_the_library_names_load_on_first_use():
    """`import pcmapq` imports no heavy library; each name of pcmapq.__all__ then resolves to
    the library's object (pcmapq.evaluate is the pipeline's evaluate)."""
    code = ("import sys, pcmapq\n"
            f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))\n"
            "from pcmapq.evaluation.pipeline import evaluate\n"
            "print(pcmapq.evaluate is evaluate, all(getattr(pcmapq, n) is not None "
            "for n in pcmapq.__all__))")
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert got.returncode == 0, got.stderr
    assert got.stdout.split("\n")[:2] == ["[]", "True True"], got.stdout
