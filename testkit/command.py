"""``pcmapq ARGS`` as a test runs it: in this process (typer's CliRunner), or in a new
interpreter; what it did: exit code, stdout, stderr, and what of it is not pcmapq's own."""

from __future__ import annotations

import subprocess
import sys
import traceback
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from typer.testing import CliRunner

import pcmapq
from pcmapq import cli
from pcmapq.cli import app, terminal

if TYPE_CHECKING:
    import pytest


@dataclass(frozen=True)
class Run:
    """What a command did: exit code, stdout, stderr (with the traceback of an exception that
    escaped the command, as a user would see it)."""

    returncode: int
    stdout: str
    stderr: str


def run(*args: str) -> Run:
    """``pcmapq ARGS`` in this process (typer's CliRunner): the same exit codes and streams as
    the installed command, without a new interpreter per call."""
    got = CliRunner().invoke(app, list(args))
    stderr = got.stderr
    if got.exception is not None and not isinstance(got.exception, SystemExit):
        stderr += "".join(traceback.format_exception(got.exception))
    return Run(got.exit_code, got.stdout, stderr)


def run_process(*args: str) -> subprocess.CompletedProcess:
    """``python -m pcmapq ARGS`` in a new interpreter: for what one process cannot show
    (identical output across processes, the module entry point)."""
    return subprocess.run([sys.executable, "-m", "pcmapq", *args], capture_output=True,
                          text=True, timeout=600)


#: pcmapq's own source folder: warnings raised from it are pcmapq's.
PCMAPQ = Path(pcmapq.__file__).parent


def foreign_lines(args: list[str], capfd: pytest.CaptureFixture[str],
                  monkeypatch: pytest.MonkeyPatch) -> tuple[int, list[str]]:
    """Run ``pcmapq ARGS``; its exit code and what of its output is not pcmapq's own: stderr
    lines (Python's, and those C++ libraries write to file descriptor 2) not starting
    "pcmapq: ", and every warning but pcmapq's own UserWarnings (the command line would print
    a NumPy RuntimeWarning as "pcmapq: warning: ...", so warnings are recorded, not shown)."""
    caught: list[warnings.WarningMessage] = []

    @contextmanager
    def recorded(console: object) -> Iterator[None]:
        with warnings.catch_warnings(record=True) as log:
            warnings.simplefilter("always")
            yield
        caught.extend(log)

    monkeypatch.setattr(terminal, "show_warnings", recorded)
    capfd.readouterr()
    got = CliRunner().invoke(cli.app, args)
    outside = capfd.readouterr()
    lines = got.stderr.splitlines() + outside.err.splitlines() + outside.out.splitlines()
    foreign = [line for line in lines if line and not line.startswith("pcmapq: ")]
    foreign += [f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})" for w in caught
                if not (issubclass(w.category, UserWarning) and PCMAPQ in Path(w.filename).parents)
                and (issubclass(w.category, RuntimeWarning) or PCMAPQ in Path(w.filename).parents)]
    return got.exit_code, foreign
