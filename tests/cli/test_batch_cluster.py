"""pcmapq batch on a Dask cluster started by hand, as on several machines: ``dask scheduler``
and two ``dask worker ADDRESS --nthreads 1`` processes on loopback. The same table and bytes as
on local processes; a worker lost in the middle of the batch loses no row; a rerun skips the
rows done. (A LocalCluster, a worker killed and restarted by its nanny: tests/cli/test_batch.py.)"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pcmapq.batch import read_rows, run_batch
from pcmapq.cli import app
from testkit.batch import write_inputs

distributed = pytest.importorskip("dask.distributed")
pytestmark = pytest.mark.skipif(os.name != "posix", reason="process groups (os.killpg): POSIX")

DASK = [sys.executable, "-m", "dask"]
#: What a batch writes over all rows, beside each row's NAME.json.
SUMMARY = ("table.csv", "table.md")


def outputs(out: Path) -> dict[str, bytes]:
    """The tables and every row's JSON in ``out``, by file name."""
    names = [*SUMMARY, *(p.name for p in out.glob("*.json"))]
    return {name: (out / name).read_bytes() for name in sorted(names)}


def batch(*args: str) -> tuple[int, list[tuple[str, str]], str]:
    """``pcmapq batch ARGS --json -`` in this process: exit code, (name, status) of each row,
    stderr."""
    got = CliRunner().invoke(app, ["batch", *args, "--json", "-"])
    if got.exception is not None and not isinstance(got.exception, SystemExit):
        raise got.exception
    rows = json.loads(got.stdout)["rows"] if got.stdout else []
    return got.exit_code, [(r["name"], r["status"]) for r in rows], got.stderr


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """A small truth, three maps of it and a broken map file, with their manifest
    (:func:`testkit.batch.write_inputs`)."""
    return write_inputs(tmp_path_factory.mktemp("cluster"))


@pytest.fixture(scope="module")
def local(inputs) -> dict[str, bytes]:
    """The manifest run on 2 local processes into ``inputs/out``: its tables and results."""
    run_batch(read_rows(inputs / "runs.csv", {}), inputs / "out", workers=2)
    return outputs(inputs / "out")


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """``dask scheduler`` on a free loopback port (no dashboard) and two ``dask worker ADDRESS
    --nthreads 1`` processes, each command in a session of its own (its nanny and worker
    process, killed together as a machine lost); the scheduler's address. Every process is
    stopped at the end, whatever happened."""
    logs = tmp_path_factory.mktemp("dask")
    started: list[subprocess.Popen] = []

    def start(*args: str) -> None:
        with open(logs / f"{len(started)}.log", "wb") as log:
            started.append(subprocess.Popen([*DASK, *args], stdout=log,
                                            stderr=subprocess.STDOUT, start_new_session=True))

    def address() -> str | None:
        """The scheduler's address from its file, once written whole."""
        try:
            return json.loads((logs / "scheduler.json").read_text())["address"]
        except (OSError, ValueError, KeyError):
            return None

    try:
        start("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
              "--scheduler-file", str(logs / "scheduler.json"))
        deadline = time.monotonic() + 60
        while address() is None:
            assert started[0].poll() is None and time.monotonic() < deadline, \
                (logs / "0.log").read_text()
            time.sleep(0.1)
        for _ in range(2):
            start("worker", address(), "--nthreads", "1", "--host", "127.0.0.1",
                  "--no-dashboard")
        with distributed.Client(address(), timeout="60s") as client:
            client.wait_for_workers(2, timeout=90)
        yield address()
    finally:
        for process in reversed(started):  # the workers, then the scheduler
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGTERM)
        for process in reversed(started):
            try:
                process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(process.pid, signal.SIGKILL)
                process.wait()


ROWS = [("straight", "computed"), ("turned", "computed"), ("broken", "failed"),
        ("scaled", "computed")]


def test_same_table_as_local(inputs, local, cluster):
    """`pcmapq batch runs.csv --out DIR --scheduler tcp://127.0.0.1:PORT --force`: the same
    table.csv, table.md and row results, byte for byte, as the batch on local processes; the
    broken row fails alike (exit 1)."""
    code, rows, err = batch(str(inputs / "runs.csv"), "--out", str(inputs / "out"),
                            "--scheduler", cluster, "--force")
    assert code == 1, err
    assert rows == ROWS
    assert outputs(inputs / "out") == local


def test_lost_worker(inputs, local, cluster):
    """A worker lost in the middle of the batch (its `dask worker` command killed, nanny and
    worker process, while it runs a row) loses no row: Dask runs the row again on the other
    worker, and the results are the same. A rerun then skips every row done. (The module's
    last test: it leaves one worker.)"""
    lost: list[str] = []
    with distributed.Client(cluster) as client:
        pids = client.run(os.getpid)  # each worker process's, by its address

        def kill_a_busy_worker(outcome) -> None:
            if lost or outcome.status != "computed":
                return
            busy = {w: keys for w, keys in client.processing().items() if keys}
            if busy:
                worker = max(busy, key=lambda w: len(busy[w]))
                os.killpg(os.getpgid(pids[worker]), signal.SIGKILL)
                lost.extend(busy[worker])

        outcomes = run_batch(read_rows(inputs / "runs.csv", {}), inputs / "out", force=True,
                             scheduler=cluster, done=kill_a_busy_worker)
        assert lost, "no row was running when the first one ended"
        assert [(o.name, o.status) for o in outcomes] == ROWS
        assert outputs(inputs / "out") == local
        deadline = time.monotonic() + 30
        while len(client.scheduler_info()["workers"]) != 1:  # the scheduler saw it go
            assert time.monotonic() < deadline
            time.sleep(0.1)
    code, rows, err = batch(str(inputs / "runs.csv"), "--out", str(inputs / "out"),
                            "--scheduler", cluster)
    assert code == 1, err
    assert rows == [(n, "failed" if s == "failed" else "skipped") for n, s in ROWS]
    assert outputs(inputs / "out") == local
