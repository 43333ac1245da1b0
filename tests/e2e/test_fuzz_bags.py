"""Damaged recordings on the command line: a small ROS 1 bag, ROS 2 bag (SQLite and MCAP
storage) and zstd-compressed MCAP, written by rosbags (``tools/fuzz_loaders.py``'s recording
seeds: a map, laser scans, odometry, transforms), cut short or with bytes flipped at random.
``pcmapq info`` and ``pcmapq map --pose-topic /odom`` either read them (exit 0) or stop with
one ``pcmapq: error: FILE: ...`` line (exit 2); never a traceback. The library-level fuzzing
of the same seeds, with every mutation: tests/e2e/test_fuzz_loaders.py."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from testkit.command import run
from tools.fuzz_loaders import read_recording, recording_seeds, run_example, write_example

SEEDS = recording_seeds()
#: The seeds damaged here (ros2_metadata, a YAML, is fuzzed by field: test_fuzz_loaders.py).
DAMAGED = ("ros1_bag", "ros2_sqlite", "ros2_mcap", "mcap_zstd")
#: Damaged copies per seed, each read by both commands.
EXAMPLES = 12
#: A cut at any offset, or one to four bits flipped.
DAMAGE = st.one_of(
    st.tuples(st.just("truncate"), st.integers(0, 1 << 20), st.just(0), st.just(b"")).map(
        lambda op: [op]),
    st.lists(st.tuples(st.just("flip"), st.integers(0, 1 << 20), st.integers(0, 7),
                       st.just(b"")), min_size=1, max_size=4))
#: Bytes whose bit 4 flipped made a traceback, by seed: rosbags' errors raised while reading
#: messages past the index (KeyError, AssertionError, ReaderError, apsw.CorruptError).
FOUND = {"ros1_bag": (9600, 11440), "ros2_sqlite": (22540,), "ros2_mcap": (5796, 14292)}


@pytest.mark.parametrize("name", sorted(SEEDS))
def test_each_recording_seed_is_read_as_it_is(tmp_path: Path, name: str,
                                              capfd: pytest.CaptureFixture[str]) -> None:
    """Its map, its odometry and its scans read, silently."""
    assert run_example(SEEDS[name], [], tmp_path) == "loaded"
    assert capfd.readouterr() == ("", "")
    got = read_recording(write_example(SEEDS[name], [], tmp_path))
    assert got.errors == () and len(got.poses) == len(got.scans) == 3


@pytest.mark.parametrize("name", DAMAGED)
def test_a_damaged_recording_is_read_or_refused_in_one_line(tmp_path: Path, name: str) -> None:
    seed = SEEDS[name]

    def check(ops: list) -> None:
        folder = Path(tempfile.mkdtemp(dir=tmp_path))
        path = write_example(seed, ops, folder)
        for args in (("info", str(path)),
                     ("map", str(path), "--pose-topic", "/odom", "--out",
                      str(folder / "map.ply"), "-q")):
            got = run(*args)
            lines = got.stderr.splitlines()
            if got.returncode == 0:
                assert not [x for x in lines if not x.startswith("pcmapq: warning: ")], \
                    got.stderr
            else:
                assert got.returncode == 2 and len(lines) == 1, got.stderr
                assert lines[0].startswith(f"pcmapq: error: {path}: "), got.stderr

    prop = given(DAMAGE)(check)
    for at in FOUND.get(name, ()):
        prop = example([("flip", at, 4, b"")])(prop)
    settings(max_examples=EXAMPLES, derandomize=True, database=None, deadline=None,
             suppress_health_check=[HealthCheck.function_scoped_fixture,
                                    HealthCheck.too_slow])(prop)()
