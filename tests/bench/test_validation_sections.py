"""bench's validation through its command line, ``python -m bench.validation --only SECTION
--check``, for the cheap sections (a few seconds each; drawings' cases run only here): every
case of the section equals its stored reference (tests/reference/validation/, numbers within
1e-6), and the section's cases and its stored references are the same set. The other sections
are left to ``python -m bench.validation --check``. Tests reach bench/ only through its command
lines, in a subprocess."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from testkit import reference
from testkit.paths import REPO, SHARED_DATA, shared

#: They read ../shared/data (and skip, saying why, where it is absent).
pytestmark = pytest.mark.realdata
#: Sections whose whole run is cheap, and the prefix of their cases' names.
SECTIONS = {"drawings": "drawings-", "fr79": "fr79-", "lidar": "lidar-",
            "floorplans": "floorplans-", "rooms": "rooms-", "building3d": "building-"}


@pytest.mark.parametrize("section", sorted(SECTIONS))
def test_every_case_has_a_reference_and_every_reference_a_case(section):
    """``--check`` exits 1 naming a case whose figures differ or that has no reference; the
    number of cases it compared is the number of references stored under the section's
    prefix, so no stored reference lacks its case."""
    shared()
    got = subprocess.run([sys.executable, "-m", "bench.validation", "--data", str(SHARED_DATA),
                          "--only", section, "--check"], cwd=REPO, capture_output=True,
                         text=True, timeout=1800)
    assert got.returncode == 0, (got.stdout + got.stderr)[-4000:]
    compared = re.search(r"^(\d+) cases equal their references$", got.stdout, re.M)
    assert compared, got.stdout
    stored = sorted(p.stem for p in reference.FOLDER.glob(f"{SECTIONS[section]}*.json"))
    assert int(compared[1]) == len(stored), stored
