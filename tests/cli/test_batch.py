"""pcmapq batch: the same JSON as single evaluations (local processes and a Dask cluster), bad
manifests, failing rows, resuming, a worker killed mid-task, on the command line and through its
runners (``batch_run``, ``pool_run``); the manifests themselves: tests/unit/batch."""

from __future__ import annotations

import csv
import json
import os
import shlex
import sys
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pcmapq.batch import Task, read_rows
from pcmapq.batch import run_batch as batch_run
from pcmapq.batch.manifest import parse_assignments
from pcmapq.batch.run import run_local as pool_run
from pcmapq.cli import app
from pcmapq.core.errors import InputError
from pcmapq.settings import Settings
from testkit.batch import MAPS, write_inputs


def cli_run(*args: str):
    """``pcmapq ARGS`` in this process: (exit code, stdout, stderr)."""
    got = CliRunner().invoke(app, list(args))
    if got.exception is not None and not isinstance(got.exception, SystemExit):
        raise got.exception
    return got.exit_code, got.stdout, got.stderr


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """A small truth, three maps of it seen from other poses and a map file that is not an
    image, with a manifest naming them (:func:`testkit.batch.write_inputs`)."""
    return write_inputs(tmp_path_factory.mktemp("batch"))


@pytest.fixture(scope="module")
def local(inputs) -> tuple[Path, dict[str, bytes], list]:
    """The manifest run on 2 local processes: (out folder, result bytes by name, outcomes)."""
    out = inputs / "out"
    outcomes = batch_run(read_rows(inputs / "runs.csv", {}), out, workers=2)
    return out, {o.name: (out / f"{o.name}.json").read_bytes() for o in outcomes
                 if not o.exit_code}, outcomes


@pytest.fixture(scope="module")
def cluster():
    """A dask.distributed LocalCluster of 2 worker processes, closed at the end. Its nannies
    set their workers' environment (MALLOC_TRIM_THRESHOLD_, OMP_NUM_THREADS ...) in this
    process's for good: put back, so that later tests' local workers start as a user's do."""
    distributed = pytest.importorskip("dask.distributed")
    environ = dict(os.environ)
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      host="127.0.0.1", dashboard_address=None) as c:
            yield c
    finally:
        os.environ.clear()
        os.environ.update(environ)


def test_noref_columns_are_evals_options(inputs):
    """noref, noref_radius, noref_voxel: the Settings and the command line eval has for
    --no-noref --noref-radius 0.2 --noref-voxel 0.02."""
    rows = read_rows(inputs / "runs.csv", {"noref": "false", "noref_radius": "0.2",
                                           "noref_voxel": "0.02"})
    assert rows[0].settings.noref == replace(Settings().noref, enabled=False, radius=0.2,
                                             voxel=0.02)
    words = shlex.split(rows[0].command({"--json": Path("/o/s.json")}))
    assert words[-5:] == ["--no-noref", "--noref-radius", "0.2", "--noref-voxel", "0.02"]
    got = CliRunner().invoke(app, ["eval", *words[2:], "--help"])  # eval knows every option
    assert got.exit_code == 0, got.stderr


@pytest.mark.parametrize("text, message", [
    ("map,truth,bogus\na.png,t.png,1\n", "row 1: unknown column 'bogus'"),
    ("map,truth,threshold\na.png,t.png,1\nb.png,t.png,-1\n",
     "row 2: threshold: expected a finite number >= 1e-06, got '-1'"),
    ("map,truth,scale\na.png,t.png,sometimes\n", "row 1: scale: expected 'fixed' or 'auto'"),
    ("name,map,truth\nx,a.png,t.png\nx,b.png,t.png\n", "row 2: name 'x' is also row 1's"),
    ("map,threshold\na.png,0.3\n", "row 1: no 'truth'"),
    ("map,truth,no_align,scale\na.png,t.png,true,auto\n", "row 1: --no-align and --scale auto"),
    ("map,truth\na.png,t.png,extra\n", "row 1: more cells than the header's 2 columns"),
    ("name,map,truth\nfigure,a.png,t.png\n", "row 1: name 'figure' is reserved"),
])
def test_bad_manifest(tmp_path, text, message):
    """A bad manifest: one InputError naming the file, the row and the problem; the command
    line says it in one line, exit 2, before any work."""
    manifest = tmp_path / "runs.csv"
    manifest.write_text(text)
    with pytest.raises(InputError, match=f"^{manifest}: {message}".replace("(", r"\(")):
        read_rows(manifest, {})
    code, _, err = cli_run("batch", str(manifest), "--out", str(tmp_path / "out"))
    assert code == 2 and err.count("\n") == 1 and err.startswith(f"pcmapq: error: {manifest}")
    assert not (tmp_path / "out").exists()


def test_local_batch_is_eval_bit_for_bit(inputs, local):
    """Each row's JSON is the one `pcmapq eval --json` writes for the same inputs and options
    (its recorded command line), byte for byte; the broken row is recorded with its exit code
    and one-line error and the others complete; the table lists all four in manifest order."""
    out, results, outcomes = local
    assert [(o.name, o.status, o.exit_code) for o in outcomes] == [
        ("straight", "computed", 0), ("turned", "computed", 0), ("broken", "failed", 2),
        ("scaled", "computed", 0)]
    broken = outcomes[2]
    assert str(inputs / "maps" / "broken.png") in broken.error and "\n" not in broken.error
    assert not (out / "broken.json").exists()
    with open(out / "table.csv") as f:
        table = list(csv.DictReader(f))
    assert [(r["name"], r["exit_code"]) for r in table] == [
        ("straight", "0"), ("turned", "0"), ("broken", "2"), ("scaled", "0")]
    assert table[2]["error"] == broken.error and table[2]["harris_quality"] == ""
    assert (out / "table.md").exists() and (out / "figure.png").exists()
    assert json.loads(results["turned"])["settings"]["matching"]["threshold"] == 0.3
    for name, data in results.items():
        command = json.loads(data)["pcmapq"]["command"]
        args = shlex.split(command)[2:]
        assert args[args.index("--json") + 1] == str(out / f"{name}.json")
        (out / f"{name}.json").unlink()  # eval writes it again, alone
        code, _, err = cli_run("eval", *args)  # as recorded: no --quiet
        assert code == 0, err
        assert (out / f"{name}.json").read_bytes() == data, name


def test_resume(inputs, local):
    """A batch interrupted part-way (one result missing, one half written) resumes: those
    rows are computed, the others skipped (their files untouched), every result as before;
    other settings, or --force, recompute a row."""
    out, results, _ = local
    rows = read_rows(inputs / "runs.csv", {})
    before = (out / "straight.json").stat().st_mtime_ns
    (out / "turned.json").unlink()
    half = (out / "scaled.json").read_bytes()
    (out / "scaled.json").write_bytes(half[:len(half) // 2])
    again = batch_run(rows, out, workers=2)
    assert [o.status for o in again] == ["skipped", "computed", "failed", "computed"]
    assert (out / "straight.json").stat().st_mtime_ns == before
    for name, data in results.items():
        assert (out / f"{name}.json").read_bytes() == data, name
    other = read_rows(inputs / "runs.csv", parse_assignments(["tau=0.1"]))[:1]
    assert batch_run(other, out, workers=1)[0].status == "computed"
    assert json.loads((out / "straight.json").read_bytes())["settings"]["distances"] == {
        "taus": [0.1]}
    forced = batch_run(rows[:1], out, workers=1, force=True)
    assert forced[0].status == "computed"
    assert (out / "straight.json").read_bytes() == results["straight"]


class DyingTask(Task):
    """A task whose worker process dies (SIGKILL) the first time it runs: when
    ``DyingTask.marker`` (a file) is absent."""

    marker: str = ""

    def outputs(self) -> dict[str, Path]:
        import os
        import signal

        if not os.path.exists(self.marker):
            Path(self.marker).touch()
            os.kill(os.getpid(), signal.SIGKILL)
        return super().outputs()


def test_local_worker_killed(inputs, local, tmp_path):
    """A local worker process killed mid-row loses no row: the unfinished rows run again in
    a new pool."""
    out, results, _ = local
    rows = read_rows(inputs / "runs.csv", {})
    marker = tmp_path / "killed"
    tasks = [Task(rows[0], out, force=True), DyingTask(rows[1], out, force=True),
             Task(rows[3], out, force=True)]
    object.__setattr__(tasks[1], "marker", str(marker))
    outcomes = pool_run(tasks, workers=2)
    assert marker.exists()
    assert [(o.name, o.exit_code) for o in outcomes] == [
        ("straight", 0), ("turned", 0), ("scaled", 0)]
    for name, data in results.items():
        assert (out / f"{name}.json").read_bytes() == data, name


def test_dask_cluster_same_bytes(inputs, local, cluster):
    """The same rows on a dask.distributed LocalCluster write the same bytes."""
    out, results, _ = local
    outcomes = batch_run(read_rows(inputs / "runs.csv", {}), out, force=True,
                         scheduler=cluster.scheduler_address)
    assert [(o.name, o.exit_code) for o in outcomes] == [
        ("straight", 0), ("turned", 0), ("broken", 2), ("scaled", 0)]
    for name, data in results.items():
        assert (out / f"{name}.json").read_bytes() == data, name


def test_dask_worker_killed_mid_task(inputs, local, cluster, tmp_path):
    """A worker process killed while it evaluates a row (once, the first time any worker
    reaches that row) loses no row: Dask runs the task again on a worker."""
    from dask.distributed import Client

    out, results, _ = local
    marker = tmp_path / "killed"

    def install(marker=str(marker)):
        import os
        import signal

        import pcmapq.batch.row as run_module

        original = run_module.evaluate

        def evaluate_or_die(map_path, *args, **kwargs):
            if Path(map_path).stem == "turned" and not os.path.exists(marker):
                open(marker, "w").close()
                os.kill(os.getpid(), signal.SIGKILL)
            return original(map_path, *args, **kwargs)

        run_module.evaluate = evaluate_or_die

    with Client(cluster.scheduler_address) as client:
        client.run(install)
    outcomes = batch_run(read_rows(inputs / "runs.csv", {}), out, force=True,
                         scheduler=cluster.scheduler_address)
    assert marker.exists()  # a worker did die in the middle of the row
    assert [(o.name, o.status) for o in outcomes] == [
        ("straight", "computed"), ("turned", "computed"), ("broken", "failed"),
        ("scaled", "computed")]
    for name, data in results.items():
        assert (out / f"{name}.json").read_bytes() == data, name


def test_cli_glob(inputs, tmp_path):
    """`pcmapq batch "maps/s*.png" --truth T --out DIR --json -`: exit 0 when every row
    passed, the rows' statuses on stdout; quiet on stderr when not a terminal."""
    code, stdout, err = cli_run("batch", str(inputs / "maps" / "s*.png"), "--truth",
                            str(inputs / "truth.png"), "--out", str(tmp_path / "o"),
                            "--workers", "2", "--json", "-", "--plot")
    assert code == 0, err
    assert err == ""
    doc = json.loads(stdout)
    assert [(r["name"], r["status"]) for r in doc["rows"]] == [
        ("scaled", "computed"), ("straight", "computed")]
    assert (tmp_path / "o" / "scaled.png").read_bytes()[:4] == b"\x89PNG"


def test_cli_gates_judge_every_row(inputs, tmp_path):
    """--fail-under harris.quality=1.01 fails every row (a quality is at most 1): exit 3, one
    line per row, the table's gates column names the figure, the rows' JSON stay eval's;
    a rerun with a gate they pass skips every row and exits 0."""
    args = ["batch", str(inputs / "maps" / "s*.png"), "--truth", str(inputs / "truth.png"),
            "--out", str(tmp_path / "o"), "--workers", "2"]
    code, _, err = cli_run(*args, "--fail-under", "harris.quality=1.01")
    assert code == 3, err
    assert err.count("pcmapq: gate failed: ") == 2 and "harris.quality = " in err
    with open(tmp_path / "o" / "table.csv", newline="") as f:
        table = list(csv.DictReader(f))
    assert [r["gates"] for r in table] == ["fail: harris.quality"] * 2
    assert [r["exit_code"] for r in table] == ["0", "0"]  # each evaluation itself finished
    assert "gates" not in json.loads((tmp_path / "o" / "straight.json").read_text())
    code, stdout, err = cli_run(*args, "--fail-under", "coverage=0", "--json", "-")
    assert code == 0, err
    assert {r["status"] for r in json.loads(stdout)["rows"]} == {"skipped"}


def test_cli_failed_row_and_missing_dask(inputs, tmp_path, monkeypatch):
    """A failed row: its line on stderr, exit 1. --scheduler without dask: one line, exit
    2."""
    manifest = tmp_path / "one.csv"
    manifest.write_text(f"map,truth\n{inputs / 'maps' / 'broken.png'},{inputs / 'truth.png'}\n")
    code, _, err = cli_run("batch", str(manifest), "--out", str(tmp_path / "o"), "--workers", "1")
    assert code == 1
    assert err.splitlines()[0].startswith("pcmapq: error: broken: ")
    code, _, err = cli_run("batch", str(manifest), "--out", str(tmp_path / "o"),
                           "--workers", "2", "--scheduler", "tcp://127.0.0.1:1")
    assert code == 2 and err.startswith("pcmapq: error: --workers") and err.count("\n") == 1
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    code, _, err = cli_run("batch", str(manifest), "--out", str(tmp_path / "o"),
                       "--scheduler", "tcp://127.0.0.1:1")
    assert code == 2
    assert err == ("pcmapq: error: --scheduler: needs dask.distributed, which is not "
                   "installed: pip install 'pcmapq[cluster]'\n")


def test_refused_row_keeps_its_verdict_and_ranks_last(inputs, tmp_path):
    """A map of another place (three round rooms) refused in a batch: its row says "another
    place", and it ranks below the scored map and above a row that failed otherwise."""
    from testkit import synth
    from testkit.files import write_image_map

    rooms = write_image_map(synth.round_rooms(), tmp_path / "rooms.png")
    truth = inputs / "truth.png"
    manifest = tmp_path / "mixed.csv"
    manifest.write_text(f"map,truth\n{inputs / 'maps' / 'broken.png'},{truth}\n{rooms},{truth}\n"
                        f"{inputs / 'maps' / MAPS[0][0]}.png,{truth}\n")
    code, _, err = cli_run("batch", str(manifest), "--out", str(tmp_path / "o"), "--workers", "1")
    assert code == 1 and "rooms: " in err and "does not seem to show the place" in err
    with open(tmp_path / "o" / "table.csv", newline="") as f:
        rows = {r["name"]: r for r in csv.DictReader(f)}
    assert rows["rooms"]["verdict"] == "another place" and rows["rooms"]["exit_code"] == "1"
    assert [rows[n]["rank"] for n in ("broken", "rooms", MAPS[0][0])] == ["3", "2", "1"]
    assert rows["broken"]["verdict"] == ""
