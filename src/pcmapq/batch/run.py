"""Running a batch: each row's task (:func:`~pcmapq.batch.row.run_row`) on local processes or
on a ``dask.distributed`` cluster, resumable and fault tolerant (a failing row is recorded and
the others go on), then the table and figure of them all, the rows judged by the gates."""

from __future__ import annotations

import json
import multiprocessing
import os
import uuid
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import replace
from pathlib import Path

from pcmapq.batch.manifest import Row
from pcmapq.batch.row import RECORDS, Outcome, Task, failed, run_row
from pcmapq.core.errors import InputError
from pcmapq.core.unused import leave_out_unused
from pcmapq.io.writers import one_line
from pcmapq.report.summary import write_summary
from pcmapq.results import gates
from pcmapq.results.gates import Gate
from pcmapq.results.rows import table_row

#: Dask reruns a task that raised this many times (the task itself never raises; a worker
#: lost mid-task is rescheduled by the scheduler, up to its ``allowed-failures``).
DASK_RETRIES = 2
#: Local pools started in turn when a worker process dies (the unfinished rows go again).
LOCAL_ROUNDS = 2


def run_local(tasks: list[Task], workers: int,
              done: Callable[[Outcome], None] = lambda o: None,
              rules: tuple[Gate, ...] | list[Gate] = ()) -> list[Outcome]:
    """Run the tasks on ``workers`` local processes (spawned, without the modules pcmapq never
    uses: :mod:`~pcmapq.core.unused`); the outcomes in task order.
    When a worker process dies (killed, out of memory), the unfinished rows run again in a
    new pool, :data:`LOCAL_ROUNDS` times at most, then are recorded as failed (exit 1)."""
    outcomes: list[Outcome | None] = [None] * len(tasks)
    pending = list(range(len(tasks)))
    context = multiprocessing.get_context("spawn")
    for _ in range(LOCAL_ROUNDS):
        broken: list[int] = []
        with ProcessPoolExecutor(max(1, min(workers, len(pending))), mp_context=context,
                                 initializer=leave_out_unused) as pool:
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
