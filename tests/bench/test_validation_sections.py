"""bench's validation through its command line, ``python -m bench.validation --only SECTION
... --check``, for the cheap sections (a few seconds each; drawings' cases run only here), in
one process: every case of the sections equals its stored reference
(tests/reference/validation/, numbers within 1e-6), and the sections' cases and their stored
references are the same set. The other sections are left to ``python -m bench.validation
--check``. Tests reach bench/ only through its command lines, in a subprocess."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from testkit import reference
from testkit.paths import REPO, SHARED_DATA, shared

#: They read ../shared/data (and skip, saying why, where it is absent).
pytestmark = pytest.mark.realdata
#: Sections whose whole run is cheap, and the prefix of their cases' names (the floor plans'
#: cases are compared by tests/realdata/test_validation.py, whose tests read their results).
SECTIONS = {"drawings": "drawings-", "fr79": "fr79-", "lidar": "lidar-", "rooms": "rooms-",
            "building3d": "building-"}


def test_every_case_has_a_reference_and_every_reference_a_case():
    """``--check`` of the cheap sections, in one process, exits 1 naming a case whose figures
    differ or that has no reference; the number of cases it compared is the number of
    references stored under the sections' prefixes, so no stored reference lacks its case."""
    shared()
    sections = [word for name in sorted(SECTIONS) for word in ("--only", name)]
    got = subprocess.run([sys.executable, "-m", "bench.validation", "--data", str(SHARED_DATA),
                          *sections, "--check"], cwd=REPO, capture_output=True, text=True,
                         timeout=1800)
    assert got.returncode == 0, (got.stdout + got.stderr)[-4000:]
    for name in SECTIONS:  # each section ran
        assert re.search(rf"^{name}: \d+ s$", got.stderr, re.M), got.stderr
    compared = re.search(r"^(\d+) cases equal their references$", got.stdout, re.M)
    assert compared, got.stdout
    stored = sorted(p.stem for prefix in SECTIONS.values()
                    for p in reference.FOLDER.glob(f"{prefix}*.json"))
    assert int(compared[1]) == len(stored), stored
