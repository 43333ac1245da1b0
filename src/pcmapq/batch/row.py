"""One row of a batch (:func:`run_row`, the task a local process or a Dask worker runs):
skipped when its saved result matches its inputs' SHA-256, settings and command line, else
evaluated with its outputs written all together; a failure is recorded with its exit code and
one-line error, never raised."""

from __future__ import annotations

import contextlib
import hashlib
import json
import threading
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

from pcmapq import __version__
from pcmapq.batch.allocator import glibc_thresholds
from pcmapq.batch.manifest import Row
from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io.digest import sha256_file
from pcmapq.io.targets import input_files
from pcmapq.io.writers import OutputSet, one_line, write_atomic
from pcmapq.results.rows import failed_row, table_row

#: The folder of DIR where each row's record (its inputs' checksums, settings, outputs) is
#: kept; hidden, so ``DIR/*.json`` holds the results only.
RECORDS = ".pcmapq-batch"
#: One row at a time in a process: a Dask worker with several threads runs its rows in turn
#: (warnings are caught per process, and matplotlib's pyplot is not thread-safe).
ONE_AT_A_TIME = threading.Lock()


@dataclass(frozen=True)
class Task:
    """One row to run: its outputs go into ``out_dir`` (absolute); ``force`` recomputes even
    a valid saved result."""

    row: Row
    out_dir: Path
    plot: bool = False
    report: bool = False
    force: bool = False

    def outputs(self) -> dict[str, Path]:
        """The row's output files by eval option: ``NAME.json``, ``NAME.png``, ``NAME.html``."""
        stem = self.out_dir / self.row.name
        wanted = {"--json": True, "--plot": self.plot, "--report": self.report}
        suffix = {"--json": ".json", "--plot": ".png", "--report": ".html"}
        return {o: stem.with_name(stem.name + suffix[o]) for o, on in wanted.items() if on}

    def record(self) -> Path:
        """The row's record: ``DIR/.pcmapq-batch/NAME.json``."""
        return self.out_dir / RECORDS / f"{self.row.name}.json"


@dataclass(frozen=True)
class Outcome:
    """How a row ended: status 'computed', 'skipped' (a valid saved result) or 'failed';
    exit_code 0 or the error's (2 bad input, 1 evaluation failed or any other error); its
    table row (:func:`~pcmapq.results.rows.table_row` or ``failed_row``); pcmapq's
    warnings while it ran."""

    name: str
    status: str
    exit_code: int
    error: str
    summary: dict
    warnings: tuple[str, ...] = ()


def run_row(task: Task) -> Outcome:
    """The task function, local or on Dask: skip the row when its saved result is valid (and
    not ``task.force``), else evaluate it and write its outputs and record atomically. Never
    raises: an error becomes a failed Outcome (InputError 2, EvaluationError 1, other 1). It
    runs with glibc's own allocator thresholds, even on a Dask worker whose environment fixes
    them (:func:`~pcmapq.batch.allocator.glibc_thresholds`)."""
    try:
        with ONE_AT_A_TIME, glibc_thresholds():
            return _run(task)
    except (InputError, EvaluationError) as exc:
        return failed(task, exc.exit_code, one_line(exc), getattr(exc, "verdict", None))
    except Exception as exc:  # noqa: BLE001 - any error is the row's, never the batch's
        return failed(task, 1, f"{type(exc).__name__}: {one_line(exc)}")


def _run(task: Task) -> Outcome:
    """:func:`run_row` without its safety net."""
    row, key = task.row, row_key(task)
    if not task.force and (doc := saved_result(task, key)) is not None:
        return Outcome(row.name, "skipped", 0, "", table_row(row.name, doc))
    return _compute(task, key)


def row_key(task: Task) -> dict:
    """What a saved result must match to be reused: pcmapq's version, the SHA-256 of every
    file the map and truth read (an image's YAML, a YAML's image), the settings and the
    ``pcmapq eval`` command line (paths and outputs), as plain JSON types."""
    row = task.row
    key = {"pcmapq": __version__, "map": checksums(row.map), "truth": checksums(row.truth),
           "settings": row.settings.to_dict(),
           "command": row.command(task.outputs())}
    return json.loads(json.dumps(key))


def checksums(path: Path) -> dict[str, str]:
    """SHA-256 (hex) of each existing file an input reads, by file name."""
    return {f.name: sha256_file(f) for f in input_files(path) if f.is_file()}


def saved_result(task: Task, key: dict) -> dict | None:
    """The row's saved result document when it is valid: its record has the same key and
    exit code 0, every output the task writes is recorded and unchanged (SHA-256), and the
    result reads as a table row. None otherwise."""
    try:
        record = json.loads(task.record().read_text(encoding="utf-8"))
        files = record["outputs"]
        if record["key"] != key or record["exit_code"] != 0 or \
                set(files) != {p.name for p in task.outputs().values()}:
            return None
        if any(sha256_file(task.out_dir / name) != digest for name, digest in files.items()):
            return None
        doc = json.loads((task.outputs()["--json"]).read_text(encoding="utf-8"))
        table_row(task.row.name, doc)
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return doc


def _compute(task: Task, key: dict) -> Outcome:
    """Evaluate the row as ``pcmapq eval`` does and write its outputs, then its record, all
    or none (:class:`OutputSet`)."""
    row, outputs = task.row, task.outputs()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = replace(evaluate(row.map, row.truth, row.settings,
                                  truth_sha256=key["truth"].get(Path(row.truth).name)),
                         command=row.command(outputs))
        text = result.to_json()
        files = {outputs["--json"]: text.encode("utf-8")}
        if task.plot or task.report:
            from pcmapq.report.html import report_html
            from pcmapq.report.plot import figure_bytes, vectorial_figure
        if task.plot:
            files[outputs["--plot"]] = figure_bytes(vectorial_figure(result), "png")
        if task.report:
            files[outputs["--report"]] = report_html(result).encode("utf-8")
    with OutputSet() as staged:
        for path, data in files.items():
            write_atomic(path, data, staged)
        record = {"key": key, "exit_code": 0, "error": "",
                  "outputs": {p.name: hashlib.sha256(d).hexdigest() for p, d in files.items()}}
        _write_record(task, record, staged)
        staged.commit()
    return Outcome(row.name, "computed", 0, "", table_row(row.name, json.loads(text)),
                   _pcmapq_warnings(caught))


def failed(task: Task, exit_code: int, error: str, verdict: str | None = None) -> Outcome:
    """A failed row (``verdict``: "another place" for a map refused as such): its record says
    so, and no output of an earlier run stays under its name (it would not be this row's
    result)."""
    row = task.row
    for path in Task(row, task.out_dir, True, True).outputs().values():
        with contextlib.suppress(OSError):
            path.unlink(missing_ok=True)
    try:
        with OutputSet() as staged:
            _write_record(task, {"key": None, "exit_code": exit_code, "error": error,
                                 "outputs": {}}, staged)
            staged.commit()
    except (InputError, OSError):
        pass  # the table still records the failure
    return Outcome(row.name, "failed", exit_code, error,
                   failed_row(row.name, str(row.map), str(row.truth), exit_code, error, verdict))


def _write_record(task: Task, record: dict, staged: OutputSet) -> None:
    task.record().parent.mkdir(exist_ok=True)
    write_atomic(task.record(), json.dumps(record, indent=2, sort_keys=True) + "\n", staged)


def _pcmapq_warnings(caught: list[warnings.WarningMessage]) -> tuple[str, ...]:
    """pcmapq's own warnings among ``caught`` (as ``pcmapq eval`` shows them), each once."""
    package = str(Path(__file__).parents[1])
    lines = [str(w.message) for w in caught
             if w.category is UserWarning and str(w.filename).startswith(package)]
    return tuple(dict.fromkeys(lines))
