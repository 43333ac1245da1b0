"""Fuzzing of every loader (``tools/fuzz_loaders.py``, bounded here to about a minute):
mutated seed files of each format either load with the documented invariants or raise one
InputError line naming the file, with nothing on stdout or stderr (the regression tests of what
it found: tests/unit/io/test_fuzz_loaders.py)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings

from tools.fuzz_loaders import MUTATIONS, Op, make_seeds, run_example

SEEDS = make_seeds()
#: Mutated inputs per seed: about half a second per seed on one core.
EXAMPLES = 200
#: Mutated inputs per recording seed (its map, odometry and scans each read: a few tenths of a
#: second an example).
RECORDING_EXAMPLES = 20


@pytest.mark.parametrize("name", sorted(SEEDS))
def test_a_mutated_file_loads_or_is_refused_in_one_line(
        tmp_path: Path, name: str, capfd: pytest.CaptureFixture[str]) -> None:
    """Byte flips, insertions, deletions, truncations, odd header fields and YAML values: the
    result holds its invariants or the InputError is one line starting with the path; no other
    exception, nothing printed, no warning, no load over 5 s or 200 MB (``run_example``)."""
    seed = SEEDS[name]

    @settings(max_examples=RECORDING_EXAMPLES if seed.reader == "recording" else EXAMPLES,
              derandomize=True, database=None, deadline=None,
              suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
    @given(MUTATIONS)
    def check(ops: list[Op]) -> None:
        folder = Path(tempfile.mkdtemp(dir=tmp_path))
        capfd.readouterr()
        run_example(seed, ops, folder)
        assert capfd.readouterr() == ("", ""), "output on stdout or stderr"

    check()
