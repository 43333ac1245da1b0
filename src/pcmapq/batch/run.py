"""Running a batch: one task function (:func:`run_row`) per row, on local processes or on a
``dask.distributed`` cluster, resumable (a row whose saved result matches its inputs' SHA-256,
settings and command line is skipped) and fault tolerant (a failing row is recorded with its
exit code and one-line error, and the others go on)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import multiprocessing
import os
import threading
import uuid
import warnings
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from pathlib import Path

from pcmapq import __version__
from pcmapq.batch.manifest import Row
from pcmapq.core.errors import EvaluationError, InputError
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io.digest import sha256_file
from pcmapq.io.targets import input_files
from pcmapq.io.writers import OutputSet, one_line, write_atomic
from pcmapq.report.style import ARROW_SCALE
from pcmapq.report.summary import write_summary
from pcmapq.results import gates
from pcmapq.results.figures import failed_row, table_row
from pcmapq.results.gates import Gate

#: The folder of DIR where each row's record (its inputs' checksums, settings, outputs) is
#: kept; hidden, so ``DIR/*.json`` holds the results only.
RECORDS = ".pcmapq-batch"
#: Dask reruns a task that raised this many times (the task itself never raises; a worker
#: lost mid-task is rescheduled by the scheduler, up to its ``allowed-failures``).
DASK_RETRIES = 2
#: Local pools started in turn when a worker process dies (the unfinished rows go again).
LOCAL_ROUNDS = 2
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
    table row (:func:`~pcmapq.results.figures.table_row` or ``failed_row``); pcmapq's
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
    raises: an error becomes a failed Outcome (InputError 2, EvaluationError 1, other 1)."""
    try:
        with ONE_AT_A_TIME:
            return _run(task)
    except (InputError, EvaluationError) as exc:
        return failed(task, exc.exit_code, one_line(exc))
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
            files[outputs["--plot"]] = figure_bytes(vectorial_figure(result, ARROW_SCALE), "png")
        if task.report:
            files[outputs["--report"]] = report_html(result, ARROW_SCALE).encode("utf-8")
    with OutputSet() as staged:
        for path, data in files.items():
            write_atomic(path, data, staged)
        record = {"key": key, "exit_code": 0, "error": "",
                  "outputs": {p.name: hashlib.sha256(d).hexdigest() for p, d in files.items()}}
        _write_record(task, record, staged)
        staged.commit()
    return Outcome(row.name, "computed", 0, "", table_row(row.name, json.loads(text)),
                   _pcmapq_warnings(caught))


def failed(task: Task, exit_code: int, error: str) -> Outcome:
    """A failed row: its record says so, and no output of an earlier run stays under its
    name (it would not be this row's result)."""
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
                   failed_row(row.name, str(row.map), str(row.truth), exit_code, error))


def _write_record(task: Task, record: dict, staged: OutputSet) -> None:
    task.record().parent.mkdir(exist_ok=True)
    write_atomic(task.record(), json.dumps(record, indent=2, sort_keys=True) + "\n", staged)


def _pcmapq_warnings(caught: list[warnings.WarningMessage]) -> tuple[str, ...]:
    """pcmapq's own warnings among ``caught`` (as ``pcmapq eval`` shows them), each once."""
    package = str(Path(__file__).parents[1])
    lines = [str(w.message) for w in caught
             if w.category is UserWarning and str(w.filename).startswith(package)]
    return tuple(dict.fromkeys(lines))


def run_local(tasks: list[Task], workers: int,
              done: Callable[[Outcome], None] = lambda o: None,
              rules: tuple[Gate, ...] | list[Gate] = ()) -> list[Outcome]:
    """Run the tasks on ``workers`` local processes (spawned); the outcomes in task order.
    When a worker process dies (killed, out of memory), the unfinished rows run again in a
    new pool, :data:`LOCAL_ROUNDS` times at most, then are recorded as failed (exit 1)."""
    outcomes: list[Outcome | None] = [None] * len(tasks)
    pending = list(range(len(tasks)))
    context = multiprocessing.get_context("spawn")
    for _ in range(LOCAL_ROUNDS):
        broken: list[int] = []
        with ProcessPoolExecutor(max(1, min(workers, len(pending))),
                                 mp_context=context) as pool:
            futures = {pool.submit(run_row, tasks[i]): i for i in pending}
            try:
                for future in as_completed(futures):
                    i = futures[future]
                    try:
                        outcomes[i] = future.result()
                    except BrokenProcessPool:
                        broken.append(i)
                        continue
                    done(outcomes[i])
            except BaseException:  # Ctrl-C: the rows not started are not run
                pool.shutdown(wait=False, cancel_futures=True)
                raise
        pending = sorted(broken)
        if not pending:
            break
    for i in pending:
        outcomes[i] = failed(tasks[i], 1, "its worker process died (killed, or out of memory?)")
        done(outcomes[i])
    return outcomes


def run_dask(tasks: list[Task], address: str,
             done: Callable[[Outcome], None] = lambda o: None) -> list[Outcome]:
    """Run the tasks on the ``dask.distributed`` cluster whose scheduler is at ``address``
    (its workers read the inputs and write DIR: paths they must see); the outcomes in task
    order. A task whose worker is lost is rescheduled by Dask."""
    try:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise InputError("--scheduler: needs dask.distributed, which is not installed: "
                         "pip install 'pcmapq[cluster]'") from None
    try:
        client = Client(address, timeout="20s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"{address}: cannot reach the Dask scheduler: {one_line(exc)}"
                         ) from None
    outcomes: list[Outcome | None] = [None] * len(tasks)
    batch = uuid.uuid4().hex  # a key of its own per run: Dask keeps results by key
    with client:
        futures = {client.submit(run_row, task, pure=False, retries=DASK_RETRIES,
                                 key=f"pcmapq-batch-{task.row.name}-{batch}"): i
                   for i, task in enumerate(tasks)}
        for future in dask_completed(list(futures)):
            i = futures[future]
            try:
                outcomes[i] = future.result()
            except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker: the row failed
                outcomes[i] = failed(tasks[i], 1, f"dask: {type(exc).__name__}: "
                                                  f"{one_line(exc)}")
            done(outcomes[i])
    return outcomes


def run_batch(rows: list[Row], out_dir: Path, *, plot: bool = False, report: bool = False,
              force: bool = False, workers: int | None = None, scheduler: str | None = None,
              done: Callable[[Outcome], None] = lambda o: None,
              rules: tuple[Gate, ...] | list[Gate] = ()) -> list[Outcome]:
    """Run every row into ``out_dir`` (made if missing) on ``workers`` local processes
    (default: one per core) or, with ``scheduler``, on that Dask cluster; then write
    ``table.csv``, ``table.md`` and ``figure.png`` there, rows in manifest order, each finished
    row judged by the gates ``rules`` (:func:`judged`). The outcomes, in that order; ``done``
    is called with each as it ends."""
    out_dir = Path(os.path.abspath(out_dir))
    try:
        (out_dir / RECORDS).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{out_dir}: --out: cannot make the folder: {one_line(exc)}") from None
    tasks = [Task(row, out_dir, plot, report, force) for row in rows]
    if scheduler is not None:
        outcomes = run_dask(tasks, scheduler, done)
    else:
        outcomes = run_local(tasks, workers or os.cpu_count() or 1, done)
    if rules:
        outcomes = [judged(o, rules, out_dir) for o in outcomes]
    write_summary([o.summary for o in outcomes], out_dir)
    return outcomes


def judged(outcome: Outcome, rules: list[Gate], out_dir: Path) -> Outcome:
    """A finished row judged by the gates on its saved JSON: its table row gains their verdict;
    a failing row's exit code becomes :data:`pcmapq.results.gates.EXIT_CODE` (3) and its error the
    failing figures. The JSON itself stays eval's (no ``gates`` block). A failed row as it is."""
    if outcome.exit_code:
        return outcome
    doc = json.loads((out_dir / f"{outcome.name}.json").read_text(encoding="utf-8"))
    verdicts = gates.check(rules, doc)
    summary = table_row(outcome.name, gates.with_gates(doc, verdicts))
    lines = [v.line() for v in verdicts if not v.passed]
    return replace(outcome, summary=summary, exit_code=gates.EXIT_CODE if lines else 0,
                   error="; ".join(lines))
