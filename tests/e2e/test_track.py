"""``pcmapq track`` end to end, on a CARMEN log generated here with a known answer.

A robot drives along the corridor of :func:`testkit.synth.building_plan` (east, 14 m), turns
left by 90 degrees into the hall at its end and drives north; at each of its 111 poses a
180-beam FLASER scan is ray-cast exactly against the plan's walls. The corrected log holds
those poses; the drifted log holds the same ranges at poses integrated again with a gain error
of :data:`GAIN` on every increment after scan :data:`K` (the first of the turn), so both
maps are the same up to scan K and the drifted one bends from there on. The truth is the
corrected log itself (as ``bench/validation/track.py`` does with real logs), or the plan
rendered as a ROS map (PNG + YAML).

Every run of the pipeline is made once per module and shared (:class:`Runs`); tests reach them
through ``runs.track_run(...)`` and ``runs.cli_run(...)``.
"""

from __future__ import annotations

import csv
import html
import io
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io.carmen import beam_angles, read_laser_scans
from pcmapq.io.writers import write_ros_map
from pcmapq.settings import Settings
from pcmapq.track import Tracked, open_run, step_ends, track_run, travelled
from pcmapq.track.drop import MIN_DROP
from pcmapq.track.outputs import HEAD
from pcmapq.track.runs import reference_poses_of
from pcmapq.track.timeline import figures_of, result_at, settings_from, track
from testkit import synth
from testkit.carmen import flaser_log

PLAN = synth.building_plan(0)
#: The path: from the corridor's west end on its centre line (the corridor lies between
#: y = 6.72 and 8.92 m), STRAIGHT steps east, TURN steps turning left by 90 degrees, NORTH
#: steps north into the hall; every step STEP_M metres. One scan per pose.
START = np.array([1.0, 7.8, 0.0])
STRAIGHT, TURN, NORTH, STEP_M = 70, 12, 28, 0.2
SCANS = STRAIGHT + TURN + NORTH + 1
BEAMS = 180
#: Seconds between scans (the FLASER timestamps).
PERIOD = 0.25
#: The drifted log: a gain of 1 + GAIN on every increment from scan K to K + 1 on, so scans
#: 0..K keep their poses and scan K + 1 is the first drifted one.
K, GAIN = STRAIGHT, 0.10
EVERY = 10
#: The figures compared before the drift (bench/validation/track.py's).
FIGURES = ("precision", "harris_quality", "hough_quality", "sift_quality",
           "wall_precision@0.1m")
TRAJECTORY = ("ape_rmse_m", "ape_max_m", "rpe_rmse_m", "rpe_rot_rmse_deg")
#: --every-m of the metres rule: no multiple of it falls on a multiple of STEP_M.
EVERY_M = 5.55


# --- the generated data ---------------------------------------------------------------------

def integrate(start: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """(K + 1, 3) poses x, y (metres), theta (radians) from a start pose and (K, 3) motions
    dx, dy (in the frame of the pose before), dtheta: the odometry's integration."""
    theta = start[2] + np.concatenate([[0.0], np.cumsum(steps[:, 2])])
    c, s = np.cos(theta[:-1]), np.sin(theta[:-1])
    dxy = np.column_stack([c * steps[:, 0] - s * steps[:, 1], s * steps[:, 0] + c * steps[:, 1]])
    return np.column_stack([start[:2] + np.vstack([[0.0, 0.0], np.cumsum(dxy, axis=0)]), theta])


def motions() -> np.ndarray:
    """The path's (SCANS - 1, 3) motions: STEP_M ahead each, turning left on TURN of them."""
    steps = np.zeros((SCANS - 1, 3))
    steps[:, 0] = STEP_M
    steps[STRAIGHT:STRAIGHT + TURN, 2] = (np.pi / 2) / TURN
    return steps


def ray_cast(poses: np.ndarray, walls: np.ndarray, beams: int = BEAMS) -> np.ndarray:
    """(K, beams) exact ranges, metres, of FLASER beams (CARMEN's angles) from ``poses``
    (K, 3) to the nearest of the segments ``walls`` (S, 4); inf where a beam hits nothing.
    Every beam against every segment at once (K x beams x S)."""
    heading = poses[:, 2:3] + beam_angles(beams)[None]
    dx, dy = np.cos(heading)[..., None], np.sin(heading)[..., None]
    ex, ey = walls[:, 2] - walls[:, 0], walls[:, 3] - walls[:, 1]
    wx = walls[:, 0] - poses[:, 0, None, None]
    wy = walls[:, 1] - poses[:, 1, None, None]
    cross = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (wx * ey - wy * ex) / cross  # along the beam
        u = (wx * dy - wy * dx) / cross  # along the wall, 0..1
    hit = (np.abs(cross) > 1e-12) & (t > 1e-9) & (u >= 0.0) & (u <= 1.0)
    return np.where(hit, t, np.inf).min(axis=2)


def flaser_prefix(log: Path, scans: int, path: Path) -> Path:
    """The first ``scans`` FLASER lines of ``log``, as their own log."""
    lines = [line for line in log.read_text().splitlines(keepends=True)
             if line.startswith("FLASER ")]
    path.write_text("".join(lines[:scans]))
    return path


@dataclass(frozen=True)
class Data:
    """The generated files (in ``folder``) and what made them."""

    folder: Path
    corrected: Path
    drifted: Path
    truth_png: Path
    poses: np.ndarray  # (SCANS, 3) the corrected poses
    drifted_poses: np.ndarray
    ranges: np.ndarray  # (SCANS, BEAMS)


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> Data:
    folder = tmp_path_factory.mktemp("track")
    steps = motions()
    poses = integrate(START, steps)
    drifted = integrate(START, np.vstack([steps[:K], steps[K:] * (1.0 + GAIN)]))
    ranges = ray_cast(poses, PLAN)
    grid = synth.plan_grid(PLAN, 0.05)
    png = write_ros_map(folder / "plan.png", synth.render(PLAN, grid), 0.05, grid.origin[:2])
    return Data(folder, flaser_log(folder / "corrected.log", ranges, poses, PERIOD),
                flaser_log(folder / "drifted.log", ranges, drifted, PERIOD), png, poses, drifted,
                ranges)


# --- the runs, each made once ---------------------------------------------------------------

@dataclass(frozen=True)
class Cli:
    code: int
    stdout: str
    stderr: str


@dataclass
class Runs:
    """The module's runs, each made on first use: the corrected and the drifted log tracked
    through the library (``track_run``, every EVERY scans, against the corrected log, with the
    corrected poses as reference), and command lines (typer's CliRunner, in this process)."""

    data: Data
    done: dict = field(default_factory=dict)

    def ends(self) -> np.ndarray:
        return step_ends(SCANS, EVERY)

    def k_step(self) -> int:
        """The first step whose map holds a drifted scan (scan K + 1: K + 2 scans)."""
        return int(np.searchsorted(self.ends(), K + 2))

    def track_run(self, name: str) -> Tracked:
        if name not in self.done:
            run = open_run(getattr(self.data, name))
            reference = reference_poses_of(self.data.corrected, len(run))
            self.done[name] = track_run(run, self.data.corrected, Settings(), self.ends(),
                                        reference=reference)
        return self.done[name]

    def cli_run(self, *args: str, again: bool = False) -> Cli:
        """``pcmapq ARGS``; ``again``: once more, even if made before."""
        key = args
        if again or key not in self.done:
            got = CliRunner().invoke(app, [str(a) for a in args])
            if got.exception is not None and not isinstance(got.exception, SystemExit):
                raise got.exception
            self.done[key] = Cli(got.exit_code, got.stdout, got.stderr)
        return self.done[key]

    def tracked_cli_run(self, out: str, *more: str, again: bool = False) -> tuple[Cli, Path]:
        """``pcmapq track DRIFTED CORRECTED --every EVERY --reference-poses CORRECTED --out
        OUT MORE``: the library's drifted run on the command line; the outcome and the out
        folder."""
        folder = self.data.folder / out
        return self.cli_run("track", self.data.drifted, self.data.corrected, "--every",
                            str(EVERY), "--reference-poses", self.data.corrected, "--out",
                            folder, *more, again=again), folder


@pytest.fixture(scope="module")
def runs(data) -> Runs:
    return Runs(data)


def values(steps, figure: str) -> np.ndarray:
    return np.array([np.nan if s.figures.get(figure) is None else s.figures[figure]
                     for s in steps])


# --- the generated log ----------------------------------------------------------------------

@pytest.mark.unit
def test_generated_logs_read_back_exactly(data: Data) -> None:
    """The logs read back as written: every beam hit a wall within CARMEN's 30 m (none is
    taken for a "no return" code), the poses to the bit, ranges to the 1e-6 m written; the
    drifted poses are the corrected ones up to scan K and move away after it."""
    assert np.isfinite(data.ranges).all() and data.ranges.max() < 30.0
    for log, poses in ((data.corrected, data.poses), (data.drifted, data.drifted_poses)):
        scans = read_laser_scans(log)
        assert scans.ranges.shape == (SCANS, BEAMS) and np.isfinite(scans.ranges).all()
        np.testing.assert_array_equal(scans.poses, poses)
        np.testing.assert_allclose(scans.ranges, data.ranges, atol=6e-7)
        np.testing.assert_allclose(scans.stamps, PERIOD * np.arange(SCANS), atol=1e-9)
    np.testing.assert_array_equal(data.drifted_poses[:K + 1], data.poses[:K + 1])
    moved = np.linalg.norm(data.drifted_poses[:, :2] - data.poses[:, :2], axis=1)
    assert (moved[K + 1:] > 0).all() and np.all(np.diff(moved[K + 1:]) > 0)
    np.testing.assert_allclose(data.poses[-1, 2], np.pi / 2, atol=1e-12)
    # the corridor's walls seen from the start, 1.08 m to the right (beam 0, at -90 degrees)
    # and 1.12 m to the left (beam 179, at +89 degrees)
    np.testing.assert_allclose(data.ranges[0, [0, -1]],
                               [7.8 - 6.72, (8.92 - 7.8) / np.cos(np.radians(1.0))], atol=1e-9)


# --- 1. drift at a known scan ---------------------------------------------------------------

def test_drift_at_a_known_scan_is_dated_by_the_worst_drop(runs: Runs) -> None:
    """Both logs tracked every 10 scans against the corrected log: every step is scored;
    before the first step holding a drifted scan (step 7, 80 scans) the two runs' figures are
    identical (same maps, same starts); from it on the drifted run's precision is at least
    MIN_DROP below its best before and below the corrected run's, its wall precision at 0.1 m
    too; the worst drop starts within 2 steps of it (measured: at it, 0.94 -> 0.84, lowest
    0.71; the dip from 0.98 to 0.94 four steps before, made up again, is none). The corrected
    run (its map a part of the truth) keeps a wall precision at 0.1 m of at least 0.99 at every
    step (measured 1.0), a precision of at least 0.8 at every step (measured 0.91-1.0: a partial
    map's features where its view ends are not the whole map's) and of at least 0.95 at the
    end (measured 1.0)."""
    corrected, drifted = runs.track_run("corrected"), runs.track_run("drifted")
    k_step = runs.k_step()
    assert k_step == 7
    assert [s.scans for s in drifted.steps] == [s.scans for s in corrected.steps] \
        == runs.ends().tolist()
    assert all(s.scored for s in corrected.steps + drifted.steps), \
        [s.note for s in corrected.steps + drifted.steps if not s.scored]

    for a, b in zip(corrected.steps[:k_step], drifted.steps[:k_step], strict=True):
        for f in FIGURES:
            assert abs(a.figures[f] - b.figures[f]) <= 0.05, (a.step, f)
        assert a.figures == b.figures and a.start == b.start, a.step

    best = np.max(values(drifted.steps[:k_step], "precision"))
    after_c, after_d = corrected.steps[k_step:], drifted.steps[k_step:]
    assert (values(after_d, "precision") <= best - MIN_DROP).all()
    assert (values(after_d, "precision") < values(after_c, "precision") - MIN_DROP).all()
    assert (values(after_d, "wall_precision@0.1m")
            < values(after_c, "wall_precision@0.1m") - MIN_DROP).all()

    drop = drifted.drop
    assert drop is not None and drop.figure == "precision"
    assert abs(drop.start - k_step) <= 2, (drop, k_step)
    assert drop.peak < k_step <= drop.low and drop.size >= 2 * MIN_DROP
    assert drifted.shown == drop.start and drifted.result is not None

    # a partial map of a perfect run wavers too (measured: 0.93 -> 0.86 at step 3, 0.07), but
    # later steps make it up: no lasting drop
    assert corrected.drop is None
    assert (values(corrected.steps, "wall_precision@0.1m") >= 0.99).all()
    assert (values(corrected.steps, "precision") >= 0.8).all()
    assert values(corrected.steps, "precision")[-1] >= 0.95


def test_precision_leaves_the_rooms_out(runs: Runs) -> None:
    """A step's ``precision``, the figure the worst drop follows, is the mean precision of
    Harris, Hough and SIFT; the rooms' precision, which falls as a growing map's rooms are
    drawn in part, is a column of its own and moves no drop."""
    steps = [s for s in runs.track_run("corrected").steps if s.scored]
    rooms_apart = 0
    for step in steps:
        f = step.figures
        parts = [f[f"{d}_precision"] for d in ("harris", "hough", "sift")
                 if f[f"{d}_precision"] is not None]
        assert f["precision"] == pytest.approx(float(np.mean(parts)), abs=1e-6)  # 6 digits
        if f["rooms_precision"] is not None:
            rooms_apart += abs(float(np.mean([*parts, f["rooms_precision"]]))
                               - f["precision"]) > 1e-5
    assert rooms_apart > 0  # the rooms were found, and the mean would differ with them


def test_the_newest_part_of_a_drifting_map_lies_off_the_truth(runs: Runs) -> None:
    """``local_offset_m``: the readings since the step before, aligned alone, move less than
    1 cm at the corrected poses and before the drift; from the first drifted step on they lie
    farther off the truth than any error of the poses can explain away: above 5 cm at every
    step. The whole map's alignment meanwhile keeps its older, larger part fitted (``slide_m``
    under 1 cm)."""
    corrected, drifted = runs.track_run("corrected"), runs.track_run("drifted")
    k_step = runs.k_step()
    assert (values(corrected.steps, "local_offset_m") < 0.01).all()
    assert (values(drifted.steps[:k_step], "local_offset_m") < 0.01).all()
    assert (values(drifted.steps[k_step:], "local_offset_m") > 0.05).all()
    assert (values(drifted.steps, "slide_m") < 0.01).all()


# --- 2. the files -----------------------------------------------------------------------------

def _number(cell: str) -> float | None:
    return None if cell == "" else float(cell)


def test_csv_and_json_hold_the_same_steps(runs: Runs) -> None:
    """``pcmapq track`` (exit 0) writes the four files; track.csv has HEAD, the figures and
    ``note``, one row per step ending at the last scan, distance increasing; track.json the
    same rows (the same keys, in the same order; its floats the CSV's), the worst drop, the
    settings and the step rule; both are the library's steps (the CLI's defaults are
    ``Settings()``'s)."""
    got, out = runs.tracked_cli_run("cli")
    assert got.code == 0, got.stderr
    for name in ("track.csv", "track.json", "track.png", "track.html"):
        assert (out / name).stat().st_size > 0, name
    assert (out / "track.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    text = (out / "track.csv").read_text()
    header = text.splitlines()[0].split(",")
    assert header[:len(HEAD)] == list(HEAD) == ["step", "scans", "time_s", "distance_m", "scored"]
    assert header[-1] == "note"
    assert set(FIGURES) | set(TRAJECTORY) | {"slide_m", "local_offset_m"} <= set(header)
    rows = list(csv.DictReader(io.StringIO(text)))
    assert [int(r["step"]) for r in rows] == list(range(len(runs.ends())))
    assert [int(r["scans"]) for r in rows] == runs.ends().tolist()
    assert int(rows[-1]["scans"]) == SCANS
    assert np.all(np.diff([float(r["distance_m"]) for r in rows]) > 0)
    np.testing.assert_allclose([float(r["time_s"]) for r in rows],
                               PERIOD * (runs.ends() - 1), atol=1e-6)

    doc = json.loads((out / "track.json").read_text())
    assert {"steps", "worst_drop", "settings", "every"} <= set(doc)
    assert doc["every"] == {"every_scans": EVERY, "every_m": None}
    assert len(doc["steps"]) == len(rows)
    for row, step in zip(rows, doc["steps"], strict=True):
        assert list(step) == header
        for key, cell in row.items():
            value = step[key]
            if key == "note" or isinstance(value, str):  # the note, the verdict
                assert cell == value
            elif isinstance(value, bool):
                assert cell == str(int(value))
            else:
                assert _number(cell) == value, (key, cell, value)

    library = runs.track_run("drifted")
    assert doc["settings"] == json.loads(json.dumps(library.settings.to_dict()))
    assert doc["worst_drop"]["start"] == library.drop.start
    for step, mine in zip(doc["steps"], library.steps, strict=True):
        for key, value in mine.figures.items():
            if isinstance(value, str):
                assert step[key] == value, (mine.step, key)
                continue
            want = None if value is None else round(value, 6) + 0.0
            assert step[key] == pytest.approx(want, abs=2e-6), (mine.step, key)


def test_outputs_name_the_inputs_and_the_step_shown(runs: Runs) -> None:
    """track.json names the run, its poses (the log's own here), the truth and the reference
    poses with how they were compared; the report says so too, and names the step it shows:
    where the worst drop starts by default, the step asked with ``--step``."""
    got, out = runs.tracked_cli_run("cli")
    assert got.code == 0, got.stderr
    doc = json.loads((out / "track.json").read_text())
    assert doc["run"] == str(runs.data.drifted) and doc["truth"] == str(runs.data.corrected)
    assert doc["poses"] == "the log's own FLASER poses"
    assert doc["reference_poses"] == str(runs.data.corrected)
    assert doc["pose_errors"] == {"align": False, "correct_scale": False, "delta": 1}
    page = (out / "track.html").read_text()
    start = doc["worst_drop"]["start"]
    assert f"Step {start} (where the worst drop starts)" in page
    assert html.escape(str(runs.data.corrected)) + "; not aligned, RPE over 1 scan" in page
    assert f"fall starts at step {start}" in page
    asked, folder = runs.tracked_cli_run("cli-step", "--step", "2")
    assert asked.code == 0, asked.stderr
    assert "Step 2 (the step asked)" in (folder / "track.html").read_text()
    beyond, folder = runs.tracked_cli_run("cli-beyond", "--step", str(len(runs.ends())))
    assert beyond.code == 2 and not folder.exists()
    assert f"the run has {len(runs.ends())} steps" in beyond.stderr


def test_track_is_repeatable_and_json_to_stdout(runs: Runs) -> None:
    """The same command twice: byte-identical track.json and track.csv. ``--json -`` prints
    track.json to stdout and nothing else; its steps are the other run's."""
    first, out = runs.tracked_cli_run("cli")
    assert first.code == 0, first.stderr
    before = {n: (out / n).read_bytes() for n in ("track.json", "track.csv")}
    again, _ = runs.tracked_cli_run("cli", again=True)
    assert again.code == 0, again.stderr
    assert {n: (out / n).read_bytes() for n in before} == before

    piped, folder = runs.tracked_cli_run("piped", "--json", "-")
    assert piped.code == 0, piped.stderr
    assert piped.stdout == (folder / "track.json").read_text()
    doc, other = json.loads(piped.stdout), json.loads(before["track.json"])
    assert doc["pcmapq"]["command"].endswith("--json -")
    for d in (doc, other):
        d["pcmapq"].pop("command")
    assert doc == other


def test_every_m_steps_at_the_first_scan_reaching_each_multiple(runs: Runs) -> None:
    """``--every-m 5.55`` against the plan drawn as a ROS map: a step at the first scan whose
    distance travelled (along the path of the generated poses) reaches 5.55, 11.1, 16.65 m,
    then the last scan; every step scored."""
    d = runs.data
    out = d.folder / "metres"
    got = runs.cli_run("track", d.corrected, d.truth_png, "--every-m", str(EVERY_M), "--out",
                       out)
    assert got.code == 0, got.stderr
    doc = json.loads((out / "track.json").read_text())
    assert doc["every"] == {"every_scans": None, "every_m": EVERY_M}
    distance = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(d.poses[:, :2], axis=0).T))])
    marks = EVERY_M * np.arange(1, int(distance[-1] // EVERY_M) + 1)
    assert len(marks) == 3
    expected = [int(np.argmax(distance >= m)) + 1 for m in marks] + [SCANS]
    steps = doc["steps"]
    assert [s["scans"] for s in steps] == expected
    for mark, step in zip(marks, steps, strict=False):
        end = step["scans"]
        assert distance[end - 2] < mark <= distance[end - 1]
        assert step["distance_m"] == pytest.approx(distance[end - 1], abs=1e-6)
    assert all(s["scored"] for s in steps), [s["note"] for s in steps]
    np.testing.assert_array_equal(expected, step_ends(SCANS, every_m=EVERY_M,
                                                      distance=travelled(
                                                          open_run(d.corrected).poses)))


# --- 3. a step is a from-scratch evaluation --------------------------------------------------

@pytest.mark.parametrize("which", ["first", "drifted", "last"])
def test_a_step_equals_a_from_scratch_evaluation(runs: Runs, which: str, tmp_path) -> None:
    """A step of the drifted run (the first, found by the global search; the first holding a
    drifted scan; the last) is the result of scoring the map of its first scans, read from
    their own log, with :func:`pcmapq.evaluation.pipeline.evaluate` (the truth prepared for
    one map) with ICP from the step's start: the same figures, to 1e-9."""
    tracked = runs.track_run("drifted")
    step = tracked.steps[{"first": 0, "drifted": runs.k_step(), "last": -1}[which]]
    assert step.scored and (step.start is None) == (which == "first")
    prefix = flaser_prefix(runs.data.drifted, step.scans, tmp_path / "prefix.log")
    run = open_run(prefix)
    assert len(run) == step.scans
    source = next(run.maps([step.scans]))
    settings = Settings()
    settings = replace(settings, noref=replace(settings.noref, enabled=False))
    if step.start is not None:
        settings = replace(settings, alignment=replace(settings.alignment, init=step.start))
    got = figures_of(evaluate(source, runs.data.corrected, settings))
    want = {k: v for k, v in step.figures.items()
            if k not in ("slide_m", "local_offset_m") and k not in TRAJECTORY}
    assert list(got) == list(want)
    for key, value in want.items():
        if value is None or got[key] is None:
            assert got[key] is value is None, key
        elif isinstance(value, str):  # the verdict
            assert got[key] == value, key
        else:
            assert math.isclose(got[key], value, rel_tol=0.0, abs_tol=1e-9), \
                (key, got[key], value)


@pytest.mark.parametrize("which", ["first", "drifted", "last"])
def test_a_steps_result_is_evaluate_on_its_map(runs: Runs, which: str) -> None:
    """A step's full result (the one the report draws) is
    :func:`pcmapq.evaluation.pipeline.evaluate` of the step's map (the run's first scans) and
    the truth file with the step's settings (the no-reference figures off, as track scores;
    ICP from the step's start): the same JSON but for ``truth_sha256``, the truth file's
    checksum that evaluate reads and a step does not."""
    tracked = runs.track_run("drifted")
    step = tracked.steps[{"first": 0, "drifted": runs.k_step(), "last": -1}[which]]
    run = open_run(runs.data.drifted)
    got = result_at(run, tracked.truth, tracked.settings, step)
    want = evaluate(next(run.maps([step.scans])), runs.data.corrected,
                    settings_from(tracked.settings, step.start))
    assert want.truth_sha256 is not None and got.truth_sha256 is None
    assert got.to_json() == replace(want, truth_sha256=None).to_json()


# --- 4. trajectory errors ---------------------------------------------------------------------

def test_reference_poses_give_no_error_before_the_drift(runs: Runs) -> None:
    """With the corrected log's poses as reference: the drifted run's APE is 0 at every step
    before the first drifted scan, and positive from it on, growing (the drift accumulates);
    the corrected run's is 0 throughout. The command line's track.json says the same."""
    k_step = runs.k_step()
    drifted, corrected = runs.track_run("drifted"), runs.track_run("corrected")
    ape = values(drifted.steps, "ape_rmse_m")
    assert (ape[:k_step] < 1e-9).all() and (ape[k_step:] > 1e-3).all()
    assert np.all(np.diff(values(drifted.steps, "ape_max_m")[k_step - 1:]) > 0)
    assert (values(corrected.steps, "ape_rmse_m") < 1e-9).all()
    assert (values(corrected.steps, "rpe_rmse_m") < 1e-9).all()

    got, out = runs.tracked_cli_run("cli")
    assert got.code == 0, got.stderr
    steps = json.loads((out / "track.json").read_text())["steps"]
    assert [s["ape_rmse_m"] for s in steps[:k_step]] == [0.0] * k_step
    assert all(s["ape_rmse_m"] > 1e-3 for s in steps[k_step:])


# --- 5. bad input -------------------------------------------------------------------------------

@pytest.mark.parametrize("quiet", [True, False])
def test_a_run_with_no_scorable_step_fails_in_one_line(runs: Runs, quiet: bool) -> None:
    """Three scans of one straight wall (nothing fixes a pose along it): every step is kept
    with its reason, and the command exits 1 with one ``pcmapq: error:`` line, its last on
    stderr (its only one with --quiet), no traceback."""
    d = runs.data
    wall = np.array([[-20.0, 2.0, 20.0, 2.0]])
    poses = np.array([[0.0, 0.0, np.pi / 2], [0.5, 0.0, np.pi / 2], [1.0, 0.0, np.pi / 2]])
    ranges = ray_cast(poses, wall)
    ranges[~(ranges < 10.0)] = 0.0  # no reading: CARMEN's "nothing within range"
    log = flaser_log(d.folder / "wall.log", ranges, poses, PERIOD)
    out = d.folder / f"wall-{quiet}"
    got = runs.cli_run("track", log, d.corrected, "--every", "1", "--out", out,
                       *(["--quiet"] if quiet else []))
    assert got.code == 1, got.stderr
    lines = got.stderr.splitlines()
    errors = [line for line in lines if line.startswith("pcmapq: error:")]
    assert len(errors) == 1 and lines[-1] == errors[0], got.stderr
    assert "no step could be scored" in errors[0] and "straight line" in errors[0]
    assert "Traceback" not in got.stderr and got.stdout == ""
    if quiet:
        assert lines == errors
    steps = json.loads((out / "track.json").read_text())["steps"]
    assert [s["scans"] for s in steps] == [1, 2, 3]
    assert all(not s["scored"] and "straight line" in s["note"] for s in steps)


def test_every_and_every_m_together_is_a_usage_error(runs: Runs) -> None:
    d = runs.data
    out = d.folder / "both"
    got = runs.cli_run("track", d.corrected, d.corrected, "--every", "10", "--every-m", "5",
                       "--out", out)
    assert got.code == 2, got.stderr
    assert "--every" in got.stderr and "Traceback" not in got.stderr
    assert not out.exists()


def test_steps_scored_one_at_a_time_equal_those_scored_at_once(runs: Runs) -> None:
    """With memory for one map at a time (``prepared.maps`` 1: no step is scored while the
    next is placed) the steps are those of the default run (three at once), figure for
    figure and start for start."""
    tracked = runs.track_run("drifted")
    run = open_run(runs.data.drifted)
    alone = track(run, replace(tracked.truth, maps=1), tracked.settings, runs.ends(),
                  reference_poses_of(runs.data.corrected, len(run)))
    assert tracked.truth.maps == 3
    assert [(s.figures, s.note, s.start) for s in alone] == \
        [(s.figures, s.note, s.start) for s in tracked.steps]


def test_a_run_over_the_memory_limit_stops_in_one_line(runs: Runs) -> None:
    """``--max-memory`` below what even one map at a time needs: exit 2, one line naming the
    truth and the limit, no outputs."""
    d = runs.data
    out = d.folder / "memory"
    got = runs.cli_run("track", d.drifted, d.corrected, "--every", str(EVERY), "--out", out,
                       "--max-memory", "0.05")
    assert got.code == 2, got.stderr
    lines = got.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pcmapq: error: {d.corrected} with 1 map")
    assert "--max-memory" in lines[0]
    assert not out.exists()
