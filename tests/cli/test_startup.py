"""`pcmapq --help` and `--version` answer without loading the pipeline: the same output as the
whole application, and none of the heavy libraries imported (they took 1.9 s and 360 MB
before any work). A command imports its own module alone, and `pcmapq inspect` not Open3D
(0.8 s) where it does not need it. Which libraries a run loads is read from `sys.modules` in a
fresh process, never from its time."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.cli.base import listing_app
from testkit.paths import SAMPLE

#: Libraries the pipeline needs and a listing must not import.
HEAVY = ("open3d", "cv2", "kiss_icp", "numpy", "scipy", "skimage", "matplotlib")
#: Libraries `pcmapq inspect` of a 3D map with its orthogonal planes given does not need.
NOT_FOR_INSPECT = ("open3d", "kiss_icp", "skimage", "matplotlib", "dask")
#: What a command's help must not load: the pipeline's libraries (NumPy, which the settings'
#: transforms hold, aside) and the pipeline itself.
NOT_FOR_HELP = ("open3d", "cv2", "kiss_icp", "scipy", "skimage", "matplotlib", "numba",
                "fastcluster", "small_gicp", "rosbags", "laspy", "pye57", "dask",
                "pcmapq.evaluation", "pcmapq.align.planar", "pcmapq.features.registry",
                "pcmapq.mapping", "pcmapq.report.table", "pcmapq.io.clouds", "pcmapq.metrics.noref")


def imported(args: list[str], modules: tuple[str, ...]) -> tuple[list[str], str]:
    """Which of ``modules`` ``pcmapq ARGS`` imports, run in a fresh process, and its output;
    the run must exit 0."""
    code = (f"import json, sys; from pcmapq.cli import main; sys.argv = ['pcmapq', *{args!r}]\n"
            "try:\n    main()\nexcept SystemExit as exit:\n    assert not exit.code, exit.code\n"
            f"print(json.dumps([m for m in {modules!r} if m in sys.modules]))")
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert got.returncode == 0, got.stderr
    return json.loads(got.stdout.strip().splitlines()[-1]), got.stdout


@pytest.mark.unit
@pytest.mark.parametrize("args", [["--help"], ["--version"], []], ids=["help", "version", "none"])
def test_the_listing_says_what_the_whole_application_says(args):
    whole = CliRunner().invoke(app, args, prog_name="pcmapq")
    listing = CliRunner().invoke(listing_app(), args, prog_name="pcmapq")
    assert (listing.exit_code, listing.output) == (whole.exit_code, whole.output)
    assert "pcmapq" in listing.output


@pytest.mark.parametrize("flag", ["--help", "--version"])
def test_help_and_version_import_no_heavy_library(flag):
    assert imported([flag], HEAVY)[0] == []


@pytest.mark.parametrize("command", ["eval", "inspect", "map", "track", "batch", "info",
                                     "compare", "config"])
def test_a_commands_help_loads_no_pipeline(command):
    """`pcmapq COMMAND --help` names the formats, the detectors and every default without
    loading the loaders, the detectors or the libraries they need (`eval --help` took 1.1-1.9 s
    and 221 MB with them)."""
    found, output = imported([command, "--help"], NOT_FOR_HELP)
    assert found == [] and "--help" in output


def test_a_command_imports_its_own_module_alone():
    """`pcmapq inspect --help`: neither the other commands' modules nor Open3D."""
    others = tuple(f"pcmapq.cli.{m}" for m in ("evaluate", "map_scans", "batch", "track"))
    found, output = imported(["inspect", "--help"], others + NOT_FOR_INSPECT)
    assert found == [] and "--orth-subset" in output


def test_inspect_of_binary_pcd_scans_loads_no_open3d(tmp_path):
    """Scans in binary PCD files, placed at their poses, with MOM's planes given: read and
    scored without Open3D."""
    rng = np.random.default_rng(0)
    scans = tmp_path / "pcs"
    scans.mkdir()
    planes = []
    for axis in range(3):  # three faces of a box corner, 1 cm noise
        face = rng.uniform(0, 2, (1500, 3))
        face[:, axis] = rng.normal(0, 0.01, 1500)
        planes.append(face)
    for k in range(3):
        points = np.concatenate(planes)[k::3].astype("<f4")
        header = ("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                  f"COUNT 1 1 1\nWIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
                  f"POINTS {len(points)}\nDATA binary\n")
        (scans / f"{k:03d}.pcd").write_bytes(header.encode() + points.tobytes())
    poses = tmp_path / "poses.txt"
    poses.write_text("1 0 0 0 0 1 0 0 0 0 1 0\n" * 3)
    np.savez(tmp_path / "orth.npz", *[p[:50] for p in planes])
    out = tmp_path / "figures.json"
    found, _ = imported(["inspect", "--scans", str(scans), "--poses", str(poses), "--noref-radius",
                         "0.2", "--orth-subset", str(tmp_path / "orth.npz"), "--json", str(out),
                         "--quiet"], NOT_FOR_INSPECT)
    assert found == []
    cloud = json.loads(out.read_text())["cloud"]
    assert cloud["points"] == 4500 and cloud["orth_subset"] == "given"
    assert cloud["mom"] is not None and 0 < cloud["mom"] < 1e-3, cloud


def test_a_command_still_gets_the_whole_application():
    got = subprocess.run([sys.executable, "-m", "pcmapq", "eval", "--help"], capture_output=True,
                         text=True, timeout=120)
    assert got.returncode == 0 and "--map-crop" in got.stdout, got.stderr


@pytest.mark.unit
def test_help_offers_what_each_command_does():
    """eval's --footprint does not offer 'seen' (only track has the scans it needs), --plot
    names the formats its extension picks, and eval's gates speak of one result, batch's of
    rows."""
    text = CliRunner().invoke(app, ["eval", "--help"], terminal_width=200).output
    footprint = next(line for line in text.splitlines() if "--footprint" in line)
    assert "seen" not in footprint and "walls" in footprint
    assert "SVG" in text and "PDF" in text
    assert "row" not in text.split("--fail-under")[1].split("--fail-over")[0]
    rows = CliRunner().invoke(app, ["batch", "--help"], terminal_width=200).output
    assert "any row" in rows.split("--fail-under")[1]


def test_dev_null_discards_an_output(tmp_path):
    """`--json /dev/null` (and any output option) discards, as Unix tools do: exit 0, no
    "wrote" line, and /dev/null is still the device."""
    import os
    import stat

    sample = SAMPLE
    got = CliRunner().invoke(app, ["eval", str(sample / "scan.ply"), str(sample / "truth.png"),
                                   "--json", os.devnull, "--plot", os.devnull, "--quiet"])
    assert got.exit_code == 0, got.stderr
    assert "wrote" not in got.stderr
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)
    got = CliRunner().invoke(app, ["inspect", str(sample / "truth.yaml"), "--json", os.devnull])
    assert got.exit_code == 0 and "wrote" not in got.stderr, got.stderr


def test_the_library_names_load_on_first_use():
    """`import pcmapq` imports no heavy library; each name of pcmapq.__all__ then resolves to
    the library's object (pcmapq.evaluate is the pipeline's evaluate)."""
    code = ("import sys, pcmapq\n"
            f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))\n"
            "from pcmapq.evaluation.pipeline import evaluate\n"
            "print(pcmapq.evaluate is evaluate, all(getattr(pcmapq, n) is not None "
            "for n in pcmapq.__all__))")
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert got.returncode == 0, got.stderr
    assert got.stdout.split("\n")[:2] == ["[]", "True True"], got.stdout


def test_an_evaluation_loads_open3d_but_not_ipython(tmp_path):
    """Open3D loads Dash, which loads IPython when it is installed (0.2-0.4 s of every run that
    aligns); the command keeps it out and still scores the sample with Open3D's ICP."""
    from importlib.machinery import PathFinder

    if PathFinder.find_spec("IPython") is None:  # on the path, whatever this process marked
        pytest.skip("IPython is not installed here: there is nothing to keep out")
    args = ["eval", str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.png"), "--json",
            str(tmp_path / "r.json"), "--quiet"]
    code = (f"import sys; from pcmapq.cli import main; sys.argv = ['pcmapq', *{args!r}]\n"
            "try:\n    main()\nexcept SystemExit as exit:\n    assert not exit.code, exit.code\n"
            "print('open3d' in sys.modules, sys.modules.get('IPython') is None)")
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert got.returncode == 0, got.stderr
    assert got.stdout.strip().splitlines()[-1] == "True True"
    assert json.loads((tmp_path / "r.json").read_text())["detectors"]


#: In a fresh process: the unused modules left out, then Open3D loaded and used.
UNUSED_LEFT_OUT = """
import sys
from pcmapq.core.unused import leave_out_unused
leave_out_unused()
import open3d
print(open3d.geometry.PointCloud().is_empty(), sorted(n for n in {names!r} if sys.modules.get(n)))
"""


def test_open3d_loads_without_the_unused_modules():
    """What the command, its batch workers and the test processes do
    (:func:`~pcmapq.core.unused.leave_out_unused`): Open3D loads and works without them."""
    from importlib.machinery import PathFinder

    from pcmapq.core.unused import UNUSED

    if not any(PathFinder.find_spec(name) for name in UNUSED):
        pytest.skip("none of the unused modules is installed here: there is nothing to leave out")
    got = subprocess.run([sys.executable, "-c", UNUSED_LEFT_OUT.format(names=UNUSED)],
                         capture_output=True, text=True, timeout=120)
    assert got.returncode == 0, got.stderr
    assert got.stdout.split() == ["True", "[]"], got.stdout


#: In a fresh process: the stand-ins put in place, then Open3D loaded and used, its Plotly
#: drawing called.
STAND_INS_IN_PLACE = """
import sys
from pcmapq.core.unused import leave_out_unused
leave_out_unused()
import open3d
print(open3d.geometry.PointCloud().is_empty(), 'plotly' in sys.modules, 'dash' in sys.modules)
try:
    open3d.visualization.draw_plotly([])
except ImportError as error:
    print(error)
"""


def test_open3d_loads_without_its_plotly_drawing():
    """Open3D's package imports its Plotly drawing, which loads Plotly and Dash (about 0.2 s of
    every process that loads Open3D); pcmapq's processes put a stand-in in its place. Open3D
    loads and works without them, and the drawing, called, says it was left out."""
    got = subprocess.run([sys.executable, "-c", STAND_INS_IN_PLACE], capture_output=True,
                         text=True, timeout=120)
    assert got.returncode == 0, got.stderr
    assert got.stdout.splitlines() == [
        "True False False",
        "open3d.visualization.draw_plotly.draw_plotly is left out of pcmapq's processes"]


#: Asks the OpenBLAS that NumPy loaded how many threads it runs, in a process that ran a command.
BLAS_THREADS = """
import ctypes, os, re, sys
from pcmapq.cli import main
sys.argv = ['pcmapq', 'info', sys.argv[1]]
try:
    main()
except SystemExit as exit:
    assert not exit.code, exit.code
import numpy
found = re.findall(r'(/\\S*scipy_openblas64_\\S*\\.so)', open('/proc/self/maps').read())
print('threads', ctypes.CDLL(found[0]).scipy_openblas_get_num_threads64_() if found else 'none')
"""


@pytest.mark.parametrize(("preset", "expected"), [(None, "1"), ("2", "2")],
                         ids=["default", "user's value"])
def test_a_command_holds_openblas_to_one_thread_unless_told(preset, expected):
    """OpenBLAS threads only spin beside the pipeline's on its small systems; a user's
    OPENBLAS_NUM_THREADS is kept."""
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if preset is not None:
        env["OPENBLAS_NUM_THREADS"] = preset
    got = subprocess.run([sys.executable, "-c", BLAS_THREADS, str(SAMPLE / "truth.yaml")],
                         capture_output=True, text=True, timeout=300, env=env)
    assert got.returncode == 0, got.stderr
    threads = got.stdout.strip().splitlines()[-1].split()[-1]
    if threads == "none":
        pytest.skip("NumPy does not use the scipy-openblas64 build here")
    assert threads == expected
