"""Outputs all or nothing: a run writes every output it was asked for or none of them, never
onto one of its inputs, never onto a device, FIFO or socket, and through a symlink (the link
stays, its target is replaced)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.core.errors import InputError
from testkit.paths import SAMPLE


def _cli(*args: str | Path) -> tuple[int, str, str]:
    """``pcmapq ARGS`` in this process: exit code, stdout, stderr."""
    got = CliRunner().invoke(app, [str(a) for a in args])
    assert got.exception is None or isinstance(got.exception, SystemExit), got.exception
    return got.exit_code, got.stdout, got.stderr


def _inputs(folder: Path) -> Path:
    """The sample's truth image and its YAML copied into ``folder``; the image."""
    for name in ("truth.png", "truth.yaml"):
        (folder / name).write_bytes((SAMPLE / name).read_bytes())
    return folder / "truth.png"


def _files(folder: Path) -> dict[str, bytes]:
    """Every entry of ``folder`` (hidden temporary files included) with its bytes."""
    return {p.name: p.read_bytes() if p.is_file() else b"" for p in folder.iterdir()}


@pytest.mark.unit
def test_a_failed_output_leaves_none_of_the_run(tmp_path: Path):
    """``--json ok.json --plot /missing/dir/p.png``: refused before any work, no ok.json."""
    truth = _inputs(tmp_path)
    before = _files(tmp_path)
    code, out, err = _cli("eval", truth, truth, "--json", tmp_path / "ok.json",
                          "--plot", tmp_path / "missing" / "p.png")
    assert code == 2 and out == ""
    line, = err.strip().splitlines()
    assert "p.png: --plot: folder" in line and "does not exist" in line
    assert _files(tmp_path) == before


@pytest.mark.unit
@pytest.mark.parametrize("case", ["same path", "symlink", "hard link", "image of the yaml",
                                  "yaml beside the image"])
def test_an_output_on_an_input_is_refused(tmp_path: Path, case: str):
    """Exit 2 and one line naming the output and the input; the inputs byte for byte as
    they were; none of the run's other outputs written."""
    truth = _inputs(tmp_path)
    given: Path = truth
    option, target = "--plot", truth
    if case == "symlink":
        (tmp_path / "alias.png").symlink_to(truth)
        target = tmp_path / "alias.png"
    elif case == "hard link":
        os.link(truth, tmp_path / "hard.png")
        target = tmp_path / "hard.png"
    elif case == "image of the yaml":
        given, option = tmp_path / "truth.yaml", "--aligned"
    elif case == "yaml beside the image":
        option, target = "--aligned", tmp_path / "truth.pgm"  # writes truth.pgm + truth.yaml
    before = _files(tmp_path)
    code, _, err = _cli("eval", given, given, "--json", tmp_path / "ok.json", option, target)
    assert code == 2
    line, = err.strip().splitlines()
    assert f"{option} would overwrite the input" in line and "truth." in line
    assert _files(tmp_path) == before


@pytest.mark.unit
def test_special_files_are_refused(tmp_path: Path):
    """A FIFO, and a symlink to /dev/stdout (a device or process file), as outputs: exit 2 and
    one line; the FIFO stays a FIFO."""
    truth = _inputs(tmp_path)
    os.mkfifo(tmp_path / "fifo.json")
    (tmp_path / "stdout.csv").symlink_to("/dev/stdout")
    for option, path, says in (("--json", tmp_path / "fifo.json", "not a regular file"),
                               ("--vectors", tmp_path / "stdout.csv", "a device or process")):
        code, out, err = _cli("eval", truth, truth, option, path)
        assert code == 2 and out == ""
        line, = err.strip().splitlines()
        assert line.startswith(f"pcmapq: error: {path}: {option}: {says}"), line
    assert (tmp_path / "fifo.json").is_fifo() and (tmp_path / "stdout.csv").is_symlink()


def test_an_output_failing_after_the_work_leaves_none(tmp_path: Path, monkeypatch):
    """The report fails after the JSON, CSV, plot and aligned map are produced: none of them
    appears, no temporary file stays, nothing goes to stdout for ``--json -``."""
    import pcmapq.report.html

    def broken(*_: object) -> str:
        raise InputError(f"{tmp_path / 'r.html'}: cannot write: No space left on device")

    monkeypatch.setattr(pcmapq.report.html, "report_html", broken)
    truth = _inputs(tmp_path)
    before = _files(tmp_path)
    outputs = ["--vectors", tmp_path / "v.csv", "--plot", tmp_path / "p.png",
               "--aligned", tmp_path / "a.png", "--transform", tmp_path / "t.txt",
               "--report", tmp_path / "r.html"]
    code, out, err = _cli("eval", truth, truth, "--no-align", "--json", tmp_path / "r.json",
                          *outputs)
    assert code == 2
    line, = err.strip().splitlines()
    assert line.endswith("r.html: cannot write: No space left on device")
    assert _files(tmp_path) == before
    code, out, _ = _cli("eval", truth, truth, "--no-align", "--json", "-", *outputs)
    assert code == 2 and out == "" and _files(tmp_path) == before


@pytest.mark.unit
def test_every_output_written_and_a_symlink_written_through(tmp_path: Path):
    truth = _inputs(tmp_path)
    (tmp_path / "runs").mkdir()
    (tmp_path / "latest.json").symlink_to("runs/r1.json")
    code, _, err = _cli("eval", truth, truth, "--no-align", "--json", tmp_path / "latest.json",
                        "--vectors", tmp_path / "v.csv", "--aligned", tmp_path / "a.png")
    assert code == 0, err
    assert [line for line in err.splitlines() if line.startswith("wrote")] == [
        f"wrote {tmp_path / n}" for n in ("latest.json", "v.csv", "a.png", "a.yaml")]
    assert os.readlink(tmp_path / "latest.json") == "runs/r1.json"
    assert json.loads((tmp_path / "runs" / "r1.json").read_text())["map"]["kind"] == "image"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "a.png", "a.yaml", "latest.json", "runs", "truth.png", "truth.yaml", "v.csv"]


def _scans(folder: Path) -> tuple[Path, Path]:
    """Three small .npy scans (a box of walls, metres) and their KITTI poses (1 m apart)."""
    scans = folder / "scans"
    scans.mkdir()
    rng = np.random.default_rng(0)
    for k in range(3):
        np.save(scans / f"{k:06d}.npy", rng.uniform(-5, 5, (500, 3)).astype(np.float32))
    poses = folder / "poses.txt"
    poses.write_text("".join(f"1 0 0 {k} 0 1 0 0 0 0 1 0\n" for k in range(3)))
    return scans, poses


@pytest.mark.unit
def test_map_outputs_all_or_none(tmp_path: Path, monkeypatch):
    """`pcmapq map`: the poses failing after the map is produced leaves no map; a pose output
    on the input poses is refused before any work, the poses byte for byte as they were."""
    import pcmapq.mapping

    scans, poses = _scans(tmp_path)
    before = _files(tmp_path)
    code, _, err = _cli("map", scans, "--poses", poses, "--out", tmp_path / "m.ply",
                        "--poses-out", poses)
    assert code == 2 and err.strip().endswith(f"--poses-out would overwrite the input '{poses}'")
    assert _files(tmp_path) == before

    def broken(path: Path, *_: object, **__: object) -> None:
        raise InputError(f"{path}: cannot write: No space left on device")

    monkeypatch.setattr(pcmapq.mapping, "write_tum_poses", broken)  # imported as map runs
    code, _, err = _cli("map", scans, "--poses", poses, "--out", tmp_path / "m.ply",
                        "--poses-out", tmp_path / "p.txt", "--tum-out", tmp_path / "t.tum")
    assert code == 2 and err.strip().endswith("t.tum: cannot write: No space left on device")
    assert _files(tmp_path) == before
    monkeypatch.undo()
    code, _, err = _cli("map", scans, "--poses", poses, "--out", tmp_path / "m.ply",
                        "--poses-out", tmp_path / "p.txt", "--tum-out", tmp_path / "t.tum")
    assert code == 0, err
    assert {"m.ply", "p.txt", "t.tum"} <= set(_files(tmp_path))
