"""Outputs all or nothing (pcmapq.io.writers): an output set writes nothing until it is
committed and leaves nothing when an error ends it; a symlink is written through (the link
stays, its target is replaced)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from pcmapq.core.errors import InputError
from pcmapq.io.writers import OutputSet, atomic_file, write_atomic


def _files(folder: Path) -> dict[str, bytes]:
    """Every entry of ``folder`` (hidden temporary files included) with its bytes."""
    return {p.name: p.read_bytes() if p.is_file() else b"" for p in folder.iterdir()}


def test_an_output_set_writes_nothing_until_committed(tmp_path: Path):
    (tmp_path / "old.csv").write_text("old\n")
    with OutputSet() as outputs:
        write_atomic(tmp_path / "a.json", "{}\n", outputs)
        write_atomic(tmp_path / "old.csv", "new\n", outputs)
        assert not (tmp_path / "a.json").exists()
        assert (tmp_path / "old.csv").read_text() == "old\n"
        assert outputs.commit() == [tmp_path / "a.json", tmp_path / "old.csv"]
    assert _files(tmp_path) == {"a.json": b"{}\n", "old.csv": b"new\n"}


def test_an_output_set_left_by_an_error_leaves_nothing(tmp_path: Path):
    (tmp_path / "old.csv").write_text("old\n")
    with pytest.raises(InputError, match="disk full"), OutputSet() as outputs:
        write_atomic(tmp_path / "a.json", "{}\n", outputs)
        write_atomic(tmp_path / "old.csv", "new\n", outputs)
        raise InputError("p.png: cannot write: disk full")
    assert _files(tmp_path) == {"old.csv": b"old\n"}  # no temporary file either


def test_a_symlink_is_written_through(tmp_path: Path):
    (tmp_path / "real.json").write_text("old\n")
    os.chmod(tmp_path / "real.json", 0o640)
    (tmp_path / "link.json").symlink_to("real.json")
    with atomic_file(tmp_path / "link.json") as f:
        f.write(b"new\n")
    assert os.readlink(tmp_path / "link.json") == "real.json"
    assert (tmp_path / "real.json").read_text() == "new\n"
    assert (tmp_path / "real.json").stat().st_mode & 0o777 == 0o640
