"""A labelled corpus for "same place, another place": (map, truth) pairs, each labelled with
whether the map shows the truth's place (``same``), a ``kind`` (clean, a degradation ladder, or
which other place) and a ``level`` on that ladder, scored the way :mod:`.same_place` scores them
(``force`` and no detectors); then how well a figure of the result (the confidence by default)
tells the two labels apart.

Same place:

- clean: synthetic plans (``synth.building_plan`` seeds 0-4) as 2D point clouds (walls' faces
  5 cm apart) and as rendered images (0.05 m per pixel, walls 0.15 m thick), each in a map frame
  turned and shifted by a known similarity (``p_truth = tf(p_map)``, :func:`frame`); the shipped
  sample (``data/sample/scan.ply`` vs ``truth.png``, its pose from ``tools/make_sample.py``);
  the real same-place pairs of :mod:`.same_place` (Intel and Freiburg 079 maps vs their plans,
  four Halmstad maps vs their layouts, Gazebo).
- degraded, on plan seeds 0-2, as points and as images (same frames as the clean ones):
  wall noise sigma 0.03 / 0.06 / 0.10 m (points: Gaussian noise of each point; images: see
  :func:`draw`: ragged walls drawn from noisy points, so their thickness jitters, plus speckle:
  a share sigma / (1 m) / 10 of the free cells marked occupied, 0.3 / 0.6 / 1 %); missing walls
  (``drop_walls`` 0.2 / 0.4 / 0.6 of the inner walls); a slow bend (``bend_segments`` about the
  plan's lower-left corner, see :data:`BENDS`: the far corner (24, 16) m moves 0.2 / 0.5 / 1.0 m,
  the far end of the bottom wall (24, 0) 0.83 times that); clutter (``clutter`` 200 / 400 / 800
  boxes of 0.5 m); a broken half (the walls right of x = 12 m turned by 5 / 10 / 15 degrees about
  the plan's middle (12, 8) m).
- CARMEN drift: the first :data:`DRIFT_SCANS` scans of the intel, fhw and aces logs placed along
  their poses re-integrated with drift 1 / 2 / 3 / 4 % (the unit of :mod:`.drift`: relative gain
  errors of the rotation and translation increments, ``1 + e * (1 + z)``, z ~ N(0, 1), seed 0)
  against the same scans at their corrected poses (readings up to 30 m); and the full-log drifted
  maps of :mod:`.same_place` (intel 0.1 and 0.5 %, fhw 0.5 %) against the corrected log.

Another place: the 44 other-place pairs of :mod:`.same_place` (30 CARMEN buildings against each
other, 12 Halmstad maps against the other layouts, Intel's and Freiburg's maps against each
other's plan); synthetic layouts that differ from the 24 x 16 m plans (:data:`OTHER_SIZES`:
``building_plan(seed, width, height)`` of other outlines, so other corridor heights, with seeds
10-34, so other rooms) as maps against plans 0-4 (points and images); the three round rooms of
``tests/test_confidence.py`` against plans 0-4; each degradation's strongest level of plans
0-2 (the ladders' maps) against two of those other layouts.

Plans of one size share much of their walls (85 % of plan 0's wall points lie within 0.1 m of
plan 1's), so every synthetic other-place pair is screened (:func:`screen`): its two layouts,
clean, are aligned by the same global search (the map's layout as points), and the pair is
dropped, not scored, when at that best pose more than :data:`MAX_SHARED` of either layout's
wall points lie within :data:`SHARED_M` of the other's walls.

Every map and truth is built lazily (a callable given a scratch folder) and deterministically
(seeded). ``run`` scores the pairs; ``roc``, ``acceptance`` and ``markdown`` analyse them.

    python -m bench.validation.corpus --out bench/results/corpus.jsonl [--data DIR]
        [--only TEXT] [--fields confidence,truth_recall] [--records FILE] [--list]

``python -m bench.validation --only corpus`` runs it as a section of docs/validation.md (its
records in the system's temporary folder, ``pcmapq-corpus.jsonl``).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import asdict, dataclass, field
from functools import lru_cache, partial
from pathlib import Path

import cv2
import numpy as np
from scipy.spatial import cKDTree

from pcmapq.align.parts import PIECES
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.evaluation.same_place import MIN_AGREEING
from pcmapq.io import PointMap
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.io.writers import write_ros_map
from pcmapq.raster.draw import points_to_grid, polygon_cells
from pcmapq.report.text import number
from pcmapq.results.result import INCONSISTENT, OTHER, SAME
from pcmapq.settings import Settings
from pcmapq.testing import synth

from . import drift, same_place
from .common import DATA, ROOT, Case, Section, header, row
from .common import Record as Figures

#: Settings of every synthetic and CARMEN pair: both metric, forced, no detectors.
RIGID = same_place.RIGID
#: Today's rule: refused below this confidence.
CURRENT = same_place.NEW_MIN_CONFIDENCE
#: Plan seeds of the clean synthetic pairs, and of the degradation ladders.
CLEAN_SEEDS = (0, 1, 2, 3, 4)
LADDER_SEEDS = (0, 1, 2)
#: Cell size of the rendered images, metres; wall thickness, metres; spacing of the clouds'
#: points along the walls' faces, metres.
RESOLUTION = 0.05
THICKNESS = 0.15
SPACING = 0.05
#: The plans' size (``building_plan``'s default), metres.
WIDTH, HEIGHT = 24.0, 16.0
#: The ladders' levels: wall noise sigma (m), share of inner walls dropped, far-corner
#: displacement of the bend (m), clutter boxes, turn of the broken half (degrees).
NOISE = (0.03, 0.06, 0.10)
MISSING = (0.2, 0.4, 0.6)
BEND = (0.2, 0.5, 1.0)
CLUTTER = (200, 400, 800)
BROKEN = (5.0, 10.0, 15.0)
#: CARMEN drift: logs, levels (relative gain errors), scans used, seed.
DRIFT_LOGS = ("intel", "fhw", "aces")
DRIFT_LEVELS = (0.01, 0.02, 0.03, 0.04)
DRIFT_SCANS = 200
DRIFT_SEED = 0
#: The shipped sample's pose (tools/make_sample.py's SCAN_POSE): x, y metres, yaw degrees.
SAMPLE_POSE = (6.0, 8.0, 37.0)
#: Other places: building plans of these sizes (width, height, metres), seeds 10 + 5 * (index
#: of the size) + k against plan k (k in CLEAN_SEEDS); the round rooms' map frame.
OTHER_SIZES = ((30.0, 12.0), (18.0, 20.0), (36.0, 10.0), (20.0, 20.0), (32.0, 18.0))
OTHER_SEED = 10
ROOMS_FRAME = 7
#: Screening of the synthetic other places: a pair is dropped when more than MAX_SHARED of
#: either layout's wall points (centre lines, SHARED_STEP apart) lie within SHARED_M of the
#: other layout's walls at the best pose of the global search.
SHARED_M = 0.1
MAX_SHARED = 0.3
SHARED_STEP = 0.05
#: Where ``python -m bench.validation --only corpus`` writes its records (to analyse them
#: again with ``--records``).
RECORDS = Path(tempfile.gettempdir()) / "pcmapq-corpus.jsonl"


def bend_rate(displacement: float) -> float:
    """Degrees per metre of ``synth.bend`` (pivot at the origin) that move the plan's far corner
    (WIDTH, HEIGHT) by ``displacement`` metres: the corner turns by k * WIDTH degrees about the
    origin, a chord of 2 r sin(angle / 2), r = |(WIDTH, HEIGHT)|."""
    r = math.hypot(WIDTH, HEIGHT)
    return math.degrees(2.0 * math.asin(displacement / (2.0 * r))) / WIDTH


#: Far-corner displacement (m) -> degrees per metre: 0.2 -> 0.0166, 0.5 -> 0.0414, 1.0 -> 0.0828.
BENDS = {d: bend_rate(d) for d in BEND}

#: Kinds of pair: the name of their level and its unit, in the order of the tables.
KINDS: dict[str, str] = {
    "clean": "",
    "sample": "",
    "real": "",
    "noise": "wall noise sigma, m",
    "missing walls": "share of inner walls dropped",
    "bend": "far corner moved, m",
    "clutter": "boxes of 0.5 m",
    "broken half": "right half turned, degrees",
    "drift": "gain error, %",
    "drift full log": "gain error, %",
    "other carmen": "",
    "other halmstad": "",
    "other floor plans": "",
    "other layout": "size of the map's layout",
    "other rooms": "",
    "other degraded": "degradation",
}
#: Other places made of synthetic layouts (screened for shared walls, see :func:`screen`).
SYNTHETIC_OTHER = ("other layout", "other rooms", "other degraded")
#: The degradation ladders.
LADDERS = ("noise", "missing walls", "bend", "clutter", "broken half", "drift")


@dataclass(frozen=True)
class Layout:
    """A synthetic place: ``synth.building_plan(seed, width, height)``, or the round rooms."""

    seed: int
    width: float = WIDTH
    height: float = HEIGHT
    rooms: bool = False

    @property
    def name(self) -> str:
        """'plan 3' (24 x 16 m), 'plan 12 30 x 12 m', or 'round rooms'."""
        if self.rooms:
            return "round rooms"
        size = "" if (self.width, self.height) == (WIDTH, HEIGHT) else (
            f" {self.width:g} x {self.height:g} m")
        return f"plan {self.seed}{size}"

    def segments(self) -> np.ndarray:
        """Its walls (N, 4), metres, in its own frame."""
        return synth.round_rooms() if self.rooms else synth.building_plan(self.seed, self.width,
                                                                    self.height)

    def frame(self) -> Similarity2D:
        """Its maps' known frame (see :func:`frame`)."""
        return frame(ROOMS_FRAME if self.rooms else self.seed)


@dataclass(frozen=True)
class Pair:
    """A map and a truth, labelled. name: unique; kind: a key of :data:`KINDS`; level: the
    ladder's level (its unit in KINDS), or a label, None when clean; same: whether the map shows
    the truth's place; form: 'points', 'image', 'log' or 'real'; build_map / build_truth: given
    a scratch folder, the map (a path or a PointMap) and the truth's path, built on demand and
    deterministic; known: p_truth = known(p_map) where known (for a degraded map: the frame of
    the map before it was degraded); note: what else the level means (or how to say it, read
    when the pair is measured); displacement: how far the degradation moves the map's walls,
    metres (or how to measure it); screen: the map's and the truth's layouts of a synthetic
    other place, screened for shared walls before it is scored."""

    name: str
    kind: str
    level: float | str | None
    same: bool
    form: str
    build_map: Callable[[Path], Path | PointMap]
    build_truth: Callable[[Path], Path]
    settings: Settings = RIGID
    known: Similarity2D | None = None
    note: str | Callable[[], str] = ""
    displacement: float | Callable[[], float] | None = None
    screen: tuple[Layout, Layout] | None = None


@dataclass
class Record:
    """One pair's result: its labels, the whole "alignment" block of ``Result.to_dict()``
    (fitness, truth recall, agreement, distinctiveness, confidence, a verdict where there is
    one), the coverage, the "consistency" block where there is one, the pose error against
    the known transform at the truth's centre (metres, degrees; None where unknown), seconds
    to build the map and truth (and screen them) and to evaluate, the error if the run failed,
    what the level means, how far the degradation moves the walls (metres); for a screened
    pair, its layouts' names, their best fitness and shared walls (:func:`screen`), and
    whether it was dropped (then nothing was scored)."""

    name: str
    kind: str
    level: float | str | None
    same: bool
    form: str
    alignment: dict = field(default_factory=dict)
    coverage: float | None = None
    consistency: dict | None = None
    pose_error_m: float | None = None
    yaw_error_deg: float | None = None
    build_seconds: float = 0.0
    seconds: float = 0.0
    error: str | None = None
    note: str = ""
    displacement_m: float | None = None
    layouts: list[str] | None = None
    best_fitness: float | None = None
    shared_walls: float | None = None
    dropped: bool = False

    def summary(self) -> dict:
        """The figures a stored reference would keep."""
        return {"alignment": self.alignment, "coverage": self.coverage,
                "consistency": self.consistency}

    def to_json(self) -> str:
        return json.dumps(asdict(self), sort_keys=True)

    @classmethod
    def from_dict(cls, doc: dict) -> Record:
        return cls(**doc)


# ---- building maps and truths ----------------------------------------------------------------

def frame(seed: int) -> Similarity2D:
    """The known map frame of plan ``seed``'s maps: p_truth = frame(seed)(p_map)."""
    return Similarity2D(tx=3.0 + 1.5 * seed, ty=-2.0 + 1.0 * seed,
                        yaw=math.radians(25.0 + 47.0 * seed))


def hull(segments: np.ndarray) -> np.ndarray:
    """The convex hull (M, 2, metres) of the segments' end points."""
    pts = segments.reshape(-1, 2).astype(np.float32)
    return cv2.convexHull(pts)[:, 0, :].astype(np.float64)


def draw(segments: np.ndarray, path: Path, noise: float = 0.0, seed: int = 0) -> Path:
    """A ROS map (``path`` .png and its YAML, RESOLUTION m per pixel) of walls (segments in
    the map frame, metres): the convex hull of the walls free, unknown around it, walls
    THICKNESS thick occupied. With ``noise`` sigma (m): the walls are the cells hit by points
    2 cm apart on the faces of walls 0.05, 0.10 and 0.15 m thick, each point moved by N(0,
    sigma) (ragged walls whose thickness jitters), and a share sigma / 10 (sigma in metres) of
    the free cells is speckle (occupied), seeded."""
    grid = synth.plan_grid(segments, RESOLUTION)
    img = np.full(grid.shape, synth.UNKNOWN, dtype=np.uint8)
    img[polygon_cells(hull(segments), grid)] = synth.FREE
    if noise <= 0:
        walls = synth.wall_quads(segments, max(THICKNESS - RESOLUTION, 1e-6))
        img[polygon_cells(walls, grid)] = synth.OCCUPIED
    else:
        pts = np.vstack([synth.wall_points(segments, 0.02, t, noise, seed + k)
                         for k, t in enumerate((0.05, 0.10, THICKNESS))])
        img[points_to_grid(pts, grid)] = synth.OCCUPIED
        rng = np.random.default_rng(seed + 1000)
        free = np.flatnonzero(img == synth.FREE)
        img.flat[rng.choice(free, size=round(noise / 10 * len(free)), replace=False)] = (
            synth.OCCUPIED)
    return write_ros_map(path, img, RESOLUTION, grid.origin[:2])


def cloud(segments: np.ndarray, name: str, noise: float = 0.0, seed: int = 0) -> PointMap:
    """Points on both faces of the walls (segments in the map frame), SPACING apart, Gaussian
    noise of std ``noise`` metres, seeded: a 2D PointMap."""
    xy = synth.wall_points(segments, SPACING, THICKNESS, noise, seed)
    return PointMap(Path(name), np.column_stack([xy, np.zeros(len(xy))]), False)


def truth_layout(layout: Layout) -> Callable[[Path], Path]:
    """A layout rendered in its own frame (the truth of every synthetic pair), written once per
    scratch folder."""
    def build(folder: Path) -> Path:
        path = folder / f"truth-{slug(layout.name)}.png"
        if not path.exists():
            draw(layout.segments(), path)
        return path
    return build


def truth_plan(seed: int) -> Callable[[Path], Path]:
    """Plan ``seed`` (24 x 16 m) rendered in its own frame."""
    return truth_layout(Layout(seed))


def broken(segments: np.ndarray, degrees: float) -> np.ndarray:
    """The plan with its right half (pieces of at most 0.1 m whose middle lies right of
    WIDTH / 2) turned by ``degrees`` about the plan's middle: a map whose second half broke
    off."""
    fine = synth.densify(segments, 0.1)
    right = (fine[:, 0] + fine[:, 2]) / 2 > WIDTH / 2
    centre = np.array([WIDTH / 2, HEIGHT / 2])
    turn = Similarity2D(yaw=math.radians(degrees))
    moved = turn.apply(fine[right].reshape(-1, 2) - centre) + centre
    out = fine.copy()
    out[right] = moved.reshape(-1, 4)
    return out


def degrade(kind: str, level: float, segments: np.ndarray, seed: int) -> tuple[np.ndarray, float]:
    """The plan degraded at ``level`` of ladder ``kind``, and the wall noise to draw it with."""
    if kind == "noise":
        return segments, float(level)
    if kind == "missing walls":
        return synth.drop_walls(segments, float(level), seed), 0.0
    if kind == "bend":
        return synth.bend_segments(segments, BENDS[float(level)]), 0.0
    if kind == "clutter":
        return synth.clutter(segments, int(level), seed), 0.0
    if kind == "broken half":
        return broken(segments, float(level)), 0.0
    raise ValueError(f"unknown degradation {kind!r}")


def synthetic_map(form: str, seed: int | Layout, kind: str | None = None, level: float = 0.0,
                  name: str = "") -> Callable[[Path], Path | PointMap]:
    """Plan ``seed`` (or a layout; degraded by ``kind`` at ``level`` when given) in its map
    frame :func:`frame`, as points or as an image."""
    layout = seed if isinstance(seed, Layout) else Layout(seed)

    def build(folder: Path) -> Path | PointMap:
        plan = layout.segments()
        segments, noise = (plan, 0.0) if kind is None else degrade(kind, level, plan,
                                                                   layout.seed)
        in_map = synth.transform_segments(segments, layout.frame().inverse())
        if form == "points":
            return cloud(in_map, name, noise, layout.seed)
        return draw(in_map, folder / f"{slug(name)}.png", noise, layout.seed)
    return build


def moved(kind: str, level: float) -> float:
    """How far degradation ``kind`` at ``level`` moves the walls of plan 0, metres: the wall
    noise's sigma (each point's offset along each axis); the largest move of a wall point for
    the bend and the broken half (the plan's far corner); 0 where walls are dropped or boxes
    added."""
    if kind == "noise":
        return float(level)
    if kind not in ("bend", "broken half"):
        return 0.0
    plan = synth.building_plan(0)
    before = synth.densify(plan, 0.1).reshape(-1, 2)
    after = (synth.bend(before, BENDS[float(level)]) if kind == "bend" else
             broken(plan, float(level)).reshape(-1, 2))
    return float(np.max(np.linalg.norm(after - before, axis=1)))


def bend_note(displacement: float) -> str:
    """What a bend level means: its rate and how far the plan's far end moves."""
    k = BENDS[displacement]
    plan = synth.building_plan(0)
    fine = synth.densify(plan, 0.1).reshape(-1, 2)
    moved = float(np.max(np.linalg.norm(synth.bend(fine, k) - fine, axis=1)))
    bottom = 2 * WIDTH * math.sin(math.radians(k * WIDTH) / 2)
    return (f"{k:.4f} deg/m: far corner moves {moved:.2f} m, far end of the bottom wall "
            f"{bottom:.2f} m")


# ---- screening synthetic other places --------------------------------------------------------

def wall_samples(segments: np.ndarray, step: float = SHARED_STEP) -> np.ndarray:
    """Points along the walls' centre lines, ``step`` metres apart (N, 2)."""
    fine = synth.densify(segments, step)
    return np.vstack([fine[:, :2], fine[:, 2:]])


def shared(a: np.ndarray, b: np.ndarray, within: float = SHARED_M) -> float:
    """The larger of the share of points ``a`` (N, 2) within ``within`` metres of points ``b``
    and of ``b`` within that of ``a``: how much of their walls two layouts share."""
    ab = float(np.mean(cKDTree(b).query(a)[0] <= within))
    ba = float(np.mean(cKDTree(a).query(b)[0] <= within))
    return max(ab, ba)


@dataclass(frozen=True)
class Screened:
    """Two layouts aligned at their best pose: that pose's fitness (the map's layout as
    points against the truth's drawn), the walls they share there (:func:`shared`), seconds."""

    fitness: float
    shared: float
    seconds: float

    @property
    def dropped(self) -> bool:
        return self.shared > MAX_SHARED


@lru_cache(maxsize=256)
def screen(map_layout: Layout, truth_layout_: Layout, folder: Path) -> Screened:
    """The map's layout, clean, as points in its map frame, aligned to the truth's layout drawn
    (the global search of every corpus pair, :data:`RIGID`), and the walls the two share at the
    pose found (once per layout pair and scratch folder)."""
    start = time.perf_counter()
    segments = synth.transform_segments(map_layout.segments(), map_layout.frame().inverse())
    result = evaluate(cloud(segments, map_layout.name), truth_layout(truth_layout_)(folder),
                      RIGID)
    placed = result.transform.apply(wall_samples(segments))
    return Screened(float(result.alignment.fitness),
                    shared(placed, wall_samples(truth_layout_.segments())),
                    time.perf_counter() - start)


# ---- CARMEN ----------------------------------------------------------------------------------

@lru_cache(maxsize=3)
def _log(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A log's first DRIFT_SCANS poses, ranges and angles (read once)."""
    poses, ranges, angles = read_flaser(path)
    return poses[:DRIFT_SCANS], ranges[:DRIFT_SCANS], angles[:DRIFT_SCANS]


def drift_map(log: Path, level: float, name: str) -> Callable[[Path], PointMap]:
    """The log's first scans placed along its poses drifted at ``level`` (seed DRIFT_SEED)."""
    def build(folder: Path) -> PointMap:
        poses, ranges, angles = _log(log)
        xy = endpoints(drift.drifted(poses, level, DRIFT_SEED), ranges, angles,
                       DEFAULT_MAX_RANGE)
        return PointMap(Path(name), np.column_stack([xy, np.zeros(len(xy))]), False)
    return build


def drift_truth(log: Path) -> Callable[[Path], Path]:
    """The same scans at the corrected poses, a .npy cloud written once per scratch folder."""
    def build(folder: Path) -> Path:
        path = folder / f"truth-{log.name.split('-corrected')[0]}-{DRIFT_SCANS}.npy"
        if not path.exists():
            poses, ranges, angles = _log(log)
            drift.save_cloud(endpoints(poses, ranges, angles, DEFAULT_MAX_RANGE), path)
        return path
    return build


def trajectory_error(poses: np.ndarray, level: float) -> tuple[float, float]:
    """The drifted trajectory's largest position (m) and heading (degrees) errors, unaligned."""
    shifted = drift.drifted(poses, level, DRIFT_SEED)
    metres = float(np.max(np.linalg.norm(shifted[:, :2] - poses[:, :2], axis=1)))
    degrees = float(np.degrees(np.max(np.abs(drift.wrap(shifted[:, 2] - poses[:, 2])))))
    return metres, degrees


def drift_note(log: Path, level: float, scans: int | None = DRIFT_SCANS) -> str:
    """The drifted trajectory's largest position and heading errors (unaligned), over the
    first ``scans`` scans (None: the whole log)."""
    poses = _log(log)[0] if scans == DRIFT_SCANS else read_flaser(log)[0][:scans]
    metres, degrees = trajectory_error(poses, level)
    return (f"{log.name.split('-corrected')[0]}: trajectory off by up to {metres:.1f} m and "
            f"{degrees:.1f} deg")


def drift_offset(log: Path, level: float, scans: int | None = DRIFT_SCANS) -> float:
    """The drifted trajectory's largest position error, metres."""
    poses = _log(log)[0] if scans == DRIFT_SCANS else read_flaser(log)[0][:scans]
    return trajectory_error(poses, level)[0]


# ---- the corpus ------------------------------------------------------------------------------

def slug(name: str) -> str:
    """A pair's name as a file name."""
    return re.sub(r"[^a-z0-9.]+", "-", name.lower()).strip("-")


def _fixed(path: Path) -> Callable[[Path], Path]:
    return lambda folder: path


def _source(source: Path | Callable[[], PointMap]) -> Callable[[Path], Path | PointMap]:
    if isinstance(source, Path):
        return _fixed(source)
    return lambda folder: source()


def _other_kind(name: str) -> str:
    if name.startswith("CARMEN"):
        return "other carmen"
    return "other halmstad" if "layout" in name else "other floor plans"


def real_pairs(data: Path) -> Iterator[Pair]:
    """The pairs of :mod:`.same_place` (its table, not its Halmstad matrix): the sample with
    its known pose, the other same-place pairs as 'real' or 'drift full log', the rest as
    other places."""
    drifts = {f"{log} drifted {100 * level:g} % vs corrected": (log, level)
              for log, level in same_place.DRIFTS}
    x, y, yaw = SAMPLE_POSE
    for p in same_place.pairs(data):
        if p.name == "sample scan vs its plan":
            kind, level, form = "sample", None, "points"
        elif p.name in drifts:
            kind, level, form = "drift full log", 100 * drifts[p.name][1], "log"
        elif p.same:
            kind, level, form = "real", None, "real"
        else:
            kind, level, form = _other_kind(p.name), None, "real"
        known = (Similarity2D(x, y, math.radians(yaw)) if kind == "sample" else
                 Similarity2D() if kind == "drift full log" else None)
        note: str | Callable[[], str] = ""
        displacement: Callable[[], float] | None = None
        if kind == "drift full log":
            log, rate = same_place.carmen(data, drifts[p.name][0]), drifts[p.name][1]
            note = partial(drift_note, log, rate, None)
            displacement = partial(drift_offset, log, rate, None)
        yield Pair(f"{kind}: {p.name}", kind, level, p.same, form, _source(p.map_source),
                   _fixed(p.truth), p.settings, known, note, displacement)


def other_layouts() -> list[Layout]:
    """The other layouts: per size of :data:`OTHER_SIZES`, one plan per seed of CLEAN_SEEDS
    (layout k of a size is paired with plan k)."""
    return [Layout(OTHER_SEED + 5 * z + k, w, h) for z, (w, h) in enumerate(OTHER_SIZES)
            for k in range(len(CLEAN_SEEDS))]


def degraded_truths(seed: int) -> list[Layout]:
    """The two other layouts that plan ``seed``'s most degraded maps are set against: sizes
    2 * seed and 2 * seed + 1 (modulo their count), each the one paired with plan ``seed``."""
    n = len(CLEAN_SEEDS)
    layouts = other_layouts()
    return [layouts[n * (z % len(OTHER_SIZES)) + seed] for z in (2 * seed, 2 * seed + 1)]


def synthetic_pairs() -> Iterator[Pair]:
    """Clean and degraded synthetic pairs of one place, then of another."""
    for form in ("points", "image"):
        for s in CLEAN_SEEDS:
            name = f"clean {form}: plan {s}"
            yield Pair(name, "clean", None, True, form, synthetic_map(form, s, name=name),
                       truth_plan(s), known=frame(s))
    ladders: dict[str, tuple] = {"noise": NOISE, "missing walls": MISSING, "bend": BEND,
                                 "clutter": CLUTTER, "broken half": BROKEN}
    for kind, levels in ladders.items():
        for form in ("points", "image"):
            for level in levels:
                note = bend_note(level) if kind == "bend" else ""
                for s in LADDER_SEEDS:
                    name = f"{kind} {form} {level:g}: plan {s}"
                    yield Pair(name, kind, level, True, form,
                               synthetic_map(form, s, kind, level, name), truth_plan(s),
                               known=frame(s), note=note,
                               displacement=lambda kind=kind, level=level: moved(kind, level))
    for form in ("points", "image"):
        for layout in other_layouts():
            plan = Layout(CLEAN_SEEDS[(layout.seed - OTHER_SEED) % len(CLEAN_SEEDS)])
            name = f"other layout {form}: {layout.name} vs {plan.name}"
            yield Pair(name, "other layout", f"{layout.width:g} x {layout.height:g} m", False,
                       form, synthetic_map(form, layout, name=name), truth_layout(plan),
                       screen=(layout, plan))
    rooms = Layout(0, rooms=True)
    for form in ("points", "image"):
        for s in CLEAN_SEEDS:
            plan = Layout(s)
            name = f"other rooms {form}: round rooms vs {plan.name}"
            yield Pair(name, "other rooms", None, False, form,
                       synthetic_map(form, rooms, name=name), truth_layout(plan),
                       screen=(rooms, plan))
    for kind, levels in ladders.items():
        for form in ("points", "image"):
            for s in LADDER_SEEDS:
                for other in degraded_truths(s):
                    name = (f"other degraded {form}: plan {s} {kind} {levels[-1]:g} vs "
                            f"{other.name}")
                    yield Pair(name, "other degraded", f"{kind} {levels[-1]:g}", False, form,
                               synthetic_map(form, s, kind, levels[-1], name),
                               truth_layout(other), screen=(Layout(s), other))


def drift_pairs(data: Path) -> Iterator[Pair]:
    """CARMEN maps from drifted poses against the corrected map of the same scans."""
    for log in DRIFT_LOGS:
        path = same_place.carmen(data, log)
        for level in DRIFT_LEVELS:
            name = f"drift {log} {100 * level:g} %"
            yield Pair(name, "drift", 100 * level, True, "log", drift_map(path, level, name),
                       drift_truth(path), known=Similarity2D(),
                       note=lambda path=path, level=level: drift_note(path, level),
                       displacement=lambda path=path, level=level: drift_offset(path, level))


def pairs(data: Path = DATA) -> list[Pair]:
    """The whole corpus: synthetic pairs always; the real ones where ``data`` holds them."""
    out = list(synthetic_pairs())
    if data.is_dir():
        out[:0] = list(real_pairs(data)) + list(drift_pairs(data))
    return out


# ---- running ---------------------------------------------------------------------------------

def pose_error(result, known: Similarity2D) -> tuple[float, float]:
    """How far the found pose puts the truth's centre from where the known one does (metres),
    and the difference of their headings (degrees)."""
    rows, cols = result.grid.shape
    centre = result.grid.pixels_to_xy(np.array([[(cols - 1) / 2, (rows - 1) / 2]]))
    found = result.transform
    where = found.apply(known.inverse().apply(centre))
    metres = float(np.linalg.norm(where - centre))
    degrees = abs((math.degrees(found.yaw - known.yaw) + 180.0) % 360.0 - 180.0)
    return metres, degrees


def measure(pair: Pair, folder: Path) -> Record:
    """Build one pair and score it."""
    record = Record(pair.name, pair.kind, pair.level, pair.same, pair.form)
    start = time.perf_counter()
    try:
        record.note = pair.note if isinstance(pair.note, str) else pair.note()
        record.displacement_m = (pair.displacement() if callable(pair.displacement) else
                                 pair.displacement)
        if pair.screen is not None:
            record.layouts = [layout.name for layout in pair.screen]
            screened = screen(*pair.screen, folder)
            record.best_fitness, record.shared_walls = screened.fitness, screened.shared
            if screened.dropped:
                record.dropped = True
                record.build_seconds = time.perf_counter() - start
                return record
        source, truth = pair.build_map(folder), pair.build_truth(folder)
        record.build_seconds = time.perf_counter() - start
        start = time.perf_counter()
        result = evaluate(source, truth, pair.settings)
        record.seconds = time.perf_counter() - start
    except Exception as err:  # a corpus run records what failed and goes on
        record.error = f"{type(err).__name__}: {err}"
        record.seconds = time.perf_counter() - start
        return record
    doc = result.to_dict(features=False)
    record.alignment = doc["alignment"]
    record.coverage = doc.get("coverage")
    record.consistency = doc.get("consistency")
    if pair.known is not None:
        record.pose_error_m, record.yaw_error_deg = pose_error(result, pair.known)
    return record


def run(pairs: Iterable[Pair], out: Path | None = None,
        progress: Callable[[Record], None] = lambda r: None) -> list[Record]:
    """Score every pair (maps built in a scratch folder, removed afterwards); with ``out``, write
    each record as one JSON line as soon as it is measured."""
    records = []
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="pcmapq_corpus_") as tmp, \
            (open(out, "w") if out is not None else _Null()) as sink:
        for pair in pairs:
            record = measure(pair, Path(tmp))
            records.append(record)
            sink.write(record.to_json() + "\n")
            sink.flush()
            progress(record)
    return records


class _Null:
    """A sink that keeps nothing."""

    def __enter__(self) -> _Null:
        return self

    def __exit__(self, *exc) -> None:
        return None

    def write(self, text: str) -> None:
        return None

    def flush(self) -> None:
        return None


def load(path: Path) -> list[Record]:
    """Records saved by :func:`run`."""
    return [Record.from_dict(json.loads(line)) for line in path.read_text().splitlines()
            if line.strip()]


# ---- analysis --------------------------------------------------------------------------------

def value(record: Record, name: str) -> float | None:
    """A numeric figure of a record by name: a key of its alignment block, one of its fields
    (coverage, pose_error_m, ...), or a dotted path ('consistency.largest_offset_m'). None when
    absent or not a number (a failed run has none)."""
    if "." in name:
        head, *rest = name.split(".")
        got = getattr(record, head, None)
        for key in rest:
            got = got.get(key) if isinstance(got, dict) else None
    elif name in record.alignment:
        got = record.alignment[name]
    else:
        got = getattr(record, name, None)
    if isinstance(got, bool) or not isinstance(got, int | float) or math.isnan(got):
        return None
    return float(got)


def accepted(record: Record, threshold: float, name: str = "confidence") -> bool:
    """Whether the figure reaches ``threshold`` (a missing figure is refused)."""
    v = value(record, name)
    return v is not None and v >= threshold


#: Thresholds of the ROC: 0 to 1 in steps of 0.01.
THRESHOLDS = tuple(round(0.01 * i, 2) for i in range(101))


@dataclass(frozen=True)
class Point:
    """One threshold of the ROC: shares of same-place and other-place pairs accepted."""

    threshold: float
    same: float
    other: float


def roc(records: list[Record], name: str = "confidence",
        thresholds: Iterable[float] = THRESHOLDS) -> list[Point]:
    """For each threshold, the share of same-place and of other-place pairs whose figure
    ``name`` reaches it."""
    same = [r for r in records if r.same]
    other = [r for r in records if not r.same]

    def share(group: list[Record], t: float) -> float:
        return sum(accepted(r, t, name) for r in group) / len(group) if group else 0.0

    return [Point(t, share(same, t), share(other, t)) for t in thresholds]


def safe(records: list[Record], name: str = "confidence",
         thresholds: Iterable[float] = THRESHOLDS) -> Point | None:
    """The lowest threshold that accepts no other-place pair, with the shares it accepts (None
    when every threshold accepts one)."""
    return next((p for p in roc(records, name, thresholds) if p.other == 0.0), None)


@dataclass(frozen=True)
class Group:
    """The pairs of one kind, form and level: how many, how many reach the threshold, and the
    figure's median, smallest and largest values (None when no pair has it)."""

    kind: str
    form: str
    level: float | str | None
    same: bool
    pairs: int
    accepted: int
    median: float | None
    low: float | None
    high: float | None

    @property
    def share(self) -> float:
        return self.accepted / self.pairs if self.pairs else 0.0


def _order(level: float | str | None) -> tuple:
    return (0, 0.0, "") if level is None else (
        (1, float(level), "") if isinstance(level, int | float) else (2, 0.0, str(level)))


def acceptance(records: list[Record], threshold: float = CURRENT,
               name: str = "confidence") -> list[Group]:
    """Per kind, form and level (in KINDS' order, then form, then level): the pairs accepted
    at ``threshold`` and the figure's median and range."""
    groups: dict[tuple, list[Record]] = {}
    for r in records:
        groups.setdefault((r.kind, r.form, r.level), []).append(r)
    kinds = list(KINDS)

    def key(k: tuple) -> tuple:
        return (kinds.index(k[0]) if k[0] in kinds else len(kinds), k[0], k[1], _order(k[2]))

    out = []
    for k in sorted(groups, key=key):
        group = groups[k]
        values = [v for r in group if (v := value(r, name)) is not None]
        out.append(Group(k[0], k[1], k[2], group[0].same, len(group),
                         sum(accepted(r, threshold, name) for r in group),
                         statistics.median(values) if values else None,
                         min(values) if values else None, max(values) if values else None))
    return out


def pose_wrong(records: list[Record], metres: float = 1.0, degrees: float = 5.0) -> list[Record]:
    """Same-place pairs with a known pose whose found pose is off by more than ``metres`` or
    ``degrees``."""
    return [r for r in records if r.same and r.pose_error_m is not None
            and (r.pose_error_m > metres or (r.yaw_error_deg or 0.0) > degrees)]


def kept(records: list[Record]) -> list[Record]:
    """The records scored: without the synthetic other places dropped by the screening."""
    return [r for r in records if not r.dropped]


def scored(record: Record) -> bool:
    """Scored by the verdict: "same place" or "same place, inconsistent map" (a failed run or
    a result without a verdict is not)."""
    return record.alignment.get("verdict") in (SAME, INCONSISTENT)


def agreeing(record: Record) -> str:
    """'k of n parts agreeing', or '' when no part was placed (the confidence settled it)."""
    parts = record.alignment.get("parts") or []
    return f"{sum(bool(p.get('agrees')) for p in parts)} of {len(parts)} parts agreeing" if (
        parts) else ""


@dataclass(frozen=True)
class Verdicts:
    """The pairs of one kind and level: how many, the forms, how many the verdict scores and
    how many of those as "same place, inconsistent map", how many the confidence alone
    accepts, the median confidence, the median largest offset of the consistency map (over
    the maps that have one) and the median displacement of the degradation (None when
    absent)."""

    kind: str
    level: float | str | None
    same: bool
    pairs: int
    forms: tuple[str, ...]
    scored: int
    inconsistent: int
    accepted: int
    confidence: float | None
    offset: float | None
    displacement: float | None

    @property
    def share(self) -> float:
        return self.scored / self.pairs if self.pairs else 0.0


def _median(values: Iterable[float | None]) -> float | None:
    got = [v for v in values if v is not None]
    return statistics.median(got) if got else None


def _kind_key(kind: str) -> tuple[int, str]:
    kinds = list(KINDS)
    return (kinds.index(kind) if kind in kinds else len(kinds), kind)


def verdict_groups(records: list[Record]) -> list[Verdicts]:
    """Per kind and level (forms together; KINDS' order, then level): the verdicts."""
    groups: dict[tuple, list[Record]] = {}
    for r in records:
        groups.setdefault((r.kind, r.level), []).append(r)
    out = []
    for (kind, level), group in sorted(groups.items(),
                                       key=lambda kv: (_kind_key(kv[0][0]), _order(kv[0][1]))):
        out.append(Verdicts(
            kind, level, group[0].same, len(group),
            tuple(dict.fromkeys(r.form for r in group)), sum(scored(r) for r in group),
            sum(r.alignment.get("verdict") == INCONSISTENT for r in group),
            sum(accepted(r, CURRENT) for r in group),
            _median(value(r, "confidence") for r in group),
            _median(value(r, "consistency.largest_offset_m") for r in group),
            _median(r.displacement_m for r in group)))
    return out


def offsets(records: list[Record], kind: str) -> list[tuple[float | str | None, float | None]]:
    """Per level of a ladder: the median largest offset of its maps' consistency maps, m."""
    return [(g.level, g.offset) for g in verdict_groups(records) if g.kind == kind]


def rising(values: list[float | None]) -> bool:
    """Whether the values grow from each level to the next (none missing)."""
    got = [v for v in values if v is not None]
    return len(got) == len(values) and all(b > a for a, b in zip(got, got[1:], strict=False))


# ---- markdown --------------------------------------------------------------------------------

def _level(level: float | str | None) -> str:
    return "-" if level is None else f"{level:g}" if isinstance(level, int | float) else level


def _spread(values: list[float], digits: int = 2) -> str:
    """'lo-hi' of some values ('-' when none)."""
    if not values:
        return "-"
    lo, hi = number(min(values), digits), number(max(values), digits)
    return lo if lo == hi else f"{lo}-{hi}"


def roc_table(records: list[Record], names: tuple[str, ...] = ("confidence",),
              steps: tuple[float, ...] = tuple(round(0.1 * i, 1) for i in range(11))) -> str:
    """Share of same-place and other-place pairs accepted per threshold, two columns per figure;
    then, per figure, the lowest threshold that accepts no other-place pair."""
    curves = {n: {p.threshold: p for p in roc(records, n, steps)} for n in names}
    lines = [header(["threshold"] + [f"{n}: {w}" for n in names for w in ("same", "other")])]
    for t in steps:
        lines.append(row([f"{t:.2f}"] + [cell for c in curves.values()
                                         for cell in (f"{100 * c[t].same:.0f} %",
                                                      f"{100 * c[t].other:.0f} %")]))
    for k, n in enumerate(names):
        s = safe(records, n)
        cells = ["-"] * (2 * len(names))
        if s is not None:
            cells[2 * k:2 * k + 2] = [f"{100 * s.same:.0f} %", f"{100 * s.other:.0f} %"]
        label = "none" if s is None else f"{s.threshold:.2f}"
        lines.append(row([f"{label} (lowest with no other place, {n})"] + cells))
    return "\n".join(lines)


def holdings_table(records: list[Record]) -> str:
    """What the corpus holds: per kind and level, the pairs, their forms and how far the
    degradation moves the walls."""
    lines = [header(["kind", "place", "level", "pairs", "forms", "walls moved, m"])]
    for g in verdict_groups(records):
        unit = KINDS.get(g.kind, "")
        lines.append(row([g.kind + (f" ({unit})" if unit else ""),
                          "same" if g.same else "other", _level(g.level), str(g.pairs),
                          ", ".join(g.forms), number(g.displacement, 2)]))
    return "\n".join(lines)


def verdicts_table(records: list[Record]) -> str:
    """Per kind and level: pairs, scored by the verdict, of them "same place, inconsistent
    map", accepted by the confidence alone, median confidence and median largest offset."""
    lines = [header(["kind", "level", "place", "pairs", "scored (verdict)",
                     "of them inconsistent", f"confidence >= {CURRENT}", "median confidence",
                     "median largest offset, m"])]
    for g in verdict_groups(records):
        wrong = g.scored < g.pairs if g.same else g.scored > 0
        cell = f"{g.scored} ({100 * g.share:.0f} %)"
        lines.append(row([g.kind, _level(g.level), "same" if g.same else "other", str(g.pairs),
                          f"**{cell}**" if wrong else cell, str(g.inconsistent),
                          str(g.accepted), number(g.confidence, 2), number(g.offset, 2)]))
    return "\n".join(lines)


def _size(name: str) -> str:
    """The group of an other layout by its name: its size ('30 x 12 m'), or 'round rooms'."""
    found = re.search(r"\d+ x \d+ m", name)
    return found.group(0) if found else name


def screening_table(records: list[Record]) -> str:
    """The screened synthetic other places per size of the other layout: layout pairs, best
    fitness and shared walls (ranges), pairs dropped."""
    groups: dict[str, list[Record]] = {}
    for r in records:
        if r.layouts:
            other = next((n for n in r.layouts if n == "round rooms" or " x " in n),
                         r.layouts[0])
            groups.setdefault(_size(other), []).append(r)
    lines = [header(["other layout", "layout pairs", "best fitness", "shared walls",
                     "pairs dropped"])]
    for size, group in groups.items():
        layouts = {tuple(r.layouts or ()): r for r in group}
        lines.append(row([size, str(len(layouts)),
                          _spread([r.best_fitness for r in layouts.values()
                                   if r.best_fitness is not None]),
                          _spread([r.shared_walls for r in layouts.values()
                                   if r.shared_walls is not None]),
                          f"{sum(r.dropped for r in group)} of {len(group)}"]))
    return "\n".join(lines)


def describe(r: Record) -> str:
    """'name (confidence c, distinctiveness d, recall r, fitness f)'."""
    a = r.alignment
    return (f"{r.name} (confidence {number(a.get('confidence'), 2)}, distinctiveness "
            f"{number(a.get('distinctiveness'), 2)}, truth recall "
            f"{number(a.get('truth_recall'), 2)}, fitness {number(a.get('fitness'), 2)})")


def largest_turn(r: Record) -> float | None:
    """How far the region of the largest offset turns, degrees (None without one)."""
    offset = value(r, "consistency.largest_offset_m")
    turns = [g.get("turn_deg") for g in (r.consistency or {}).get("regions", [])
             if offset is not None and g.get("held") and g.get("offset_m") == offset]
    return abs(float(turns[0])) if turns and isinstance(turns[0], int | float) else None


#: A largest offset whose region turns by more than this (degrees) fits walls elsewhere.
ELSEWHERE_DEG = 45.0


def wrong_line(r: Record) -> str:
    """'- name: verdict, confidence c, k of n parts agreeing, largest offset m (the turn of its
    region), shared walls'."""
    a = r.alignment
    cells = [f"\"{a.get('verdict', r.error or 'no verdict')}\"",
             f"confidence {number(a.get('confidence'), 2)}"]
    cells += [part] if (part := agreeing(r)) else []
    offset = value(r, "consistency.largest_offset_m")
    if offset is not None:
        turn = largest_turn(r)
        cells += [f"largest offset {number(offset, 2)} m" + (
            "" if turn is None else f" (its region turned {turn:.0f} degrees)")]
    cells += [] if r.shared_walls is None else [
        f"its layouts share {100 * r.shared_walls:.0f} % of their walls at their best pose"]
    return f"- {r.name}: " + ", ".join(cells)


KIND_TEXT = {
    "clean": "synthetic plans (`synth.building_plan` seeds 0-4, 24 x 16 m: outer walls, a "
             "corridor 2.2 m wide with rooms of random widths on both sides, an L-shaped wall, "
             "two pillars) in a map frame turned and shifted by a known transform, as a point "
             f"cloud (both faces of {THICKNESS} m walls, points {SPACING} m apart) and as an "
             f"image ({RESOLUTION} m per pixel), against the plan drawn as an image",
    "sample": "the shipped sample (`data/sample/scan.ply` against `truth.png`)",
    "real": "the real same-place maps of the section above (Intel and Freiburg 079 maps against "
            "their plans, four Halmstad maps against their layouts, Gazebo)",
    "noise": "plans 0-2 with every wall point moved by Gaussian noise of sigma (images: ragged "
             "walls drawn from such points, and a share sigma / (1 m) / 10 of the free cells "
             "marked occupied)",
    "missing walls": "plans 0-2 with that share of the inner walls dropped",
    "bend": "plans 0-2 bent about their lower-left corner (`synth.bend_segments`) so that the "
            "far corner moves by the level",
    "clutter": "plans 0-2 with that many boxes of 0.5 m added in the free space",
    "broken half": "plans 0-2 with the walls right of x = 12 m turned by the level about the "
                   "plan's middle (12, 8) m",
    "drift": f"the first {DRIFT_SCANS} scans of the CARMEN logs "
             f"{', '.join(DRIFT_LOGS)} placed along their poses re-integrated with a relative "
             "gain error of the level on every rotation and translation increment (seed 0), "
             "against the same scans at their corrected poses",
    "drift full log": "whole CARMEN logs re-integrated the same way, against the corrected log",
    "other carmen": "every CARMEN building's log against every other's",
    "other halmstad": "the Halmstad maps against the three other buildings' layouts",
    "other floor plans": "the Intel and Freiburg 079 maps against each other's plan",
    "other layout": "`synth.building_plan(seed, width, height)` of another outline (so the "
                    "corridor lies at another height) and another seed (so other rooms), as "
                    "points and images, against plans 0-4",
    "other rooms": "three round rooms (radii 5, 4 and 3 m) against plans 0-4",
    "other degraded": "the strongest level of each degradation of plans 0-2 (the maps of the "
                      "ladders) against two other layouts each",
}


def markdown(records: list[Record], names: tuple[str, ...] = ("confidence",),
             seconds: float | None = None) -> str:
    """The corpus's section: what it holds, the verdicts per kind and level, the real other
    places, the largest offsets, the ROC, the screening, the pairs that go wrong, wrong poses
    and failures. ``seconds``: the run's time (else the records' own)."""
    dropped = [r for r in records if r.dropped]
    screened = [r for r in records if r.layouts]
    everything = records
    records = kept(records)
    same = [r for r in records if r.same]
    other = [r for r in records if not r.same]
    if seconds is None:
        seconds = sum(r.seconds + r.build_seconds for r in everything)
    parts = PIECES[0] * PIECES[1]
    kinds = list(dict.fromkeys(r.kind for r in sorted(records, key=lambda r: _kind_key(r.kind))))
    lines = [
        "## Same place, inconsistent map, or another place: a labelled corpus", "",
        f"{len(records)} pairs of a map and a truth, each labelled with whether the map shows "
        f"the truth's place ({len(same)} do, {len(other)} show another place), scored with "
        "`force` and no detectors (`python -m bench.validation --only corpus`, or "
        "`python -m bench.validation.corpus`, which also analyses saved records again; "
        "`bench/validation/corpus.py` builds every pair, seeded). The verdict is the result's "
        f"`alignment.verdict`: \"{SAME}\" at confidence {CURRENT} or more; below it "
        f"\"{INCONSISTENT}\" when at least {MIN_AGREEING} of the map's {parts} parts, each "
        "placed on its own by the global search, land near the map's pose; else "
        f"\"{OTHER}\", refused unless forced. A pair is *scored* when its verdict is not "
        f"\"{OTHER}\". The whole corpus ran in {seconds:.0f} s.", "",
        "### What the corpus holds", "",
        holdings_table(records), "",
        "\"walls moved\" is how far the degradation moves the map's walls (median of the "
        "level's pairs): the noise's sigma along each axis; the largest move of a wall point "
        "for a bend or a broken half (the plan's far corner); 0 where walls are dropped or "
        "boxes added; for drift, the largest position error of the drifted trajectory.", "",
        *(f"- {kind}: {KIND_TEXT[kind]}." for kind in kinds if kind in KIND_TEXT),
    ]
    if screened:
        lines += [
            "", f"Plans of one size share much of their walls, so a synthetic other place "
            "is screened before it is scored: its two layouts, clean, are aligned by the same "
            "global search (the map's layout as points) and the pair is dropped when, at that "
            f"best pose, more than {100 * MAX_SHARED:.0f} % of either layout's wall points "
            f"(centre lines, {SHARED_STEP} m apart) lie within {SHARED_M} m of the other's "
            f"walls. {len(dropped)} of the {len(screened)} synthetic other-place pairs were "
            f"dropped; {len(screened) - len(dropped)} remain:", "",
            screening_table(everything)]
    lines += ["", "### Verdicts per kind and level", "",
              "Counts in bold are wrong: a same-place map refused, another place scored. "
              "\"median largest offset\": `consistency.largest_offset_m`, the largest offset "
              "that fits a held 4 m region of the map to the truth on its own, median over the "
              "level's scored maps.", "", verdicts_table(records), ""]
    real_other = [r for r in other if r.kind not in SYNTHETIC_OTHER]
    real_scored = [r for r in real_other if scored(r)]
    synth_other = [r for r in other if r.kind in SYNTHETIC_OTHER]
    lines += [f"Real other places scored: {len(real_scored)} of {len(real_other)}"
              + (":" if real_scored else "."), *(wrong_line(r) for r in real_scored)]
    if synth_other:
        lines += ["", f"Synthetic other places scored: "
                      f"{sum(scored(r) for r in synth_other)} of {len(synth_other)}."]
    growth = []
    for kind, unit in (("bend", "m of the far corner"), ("broken half", "degrees"),
                       ("drift", "% of drift")):
        levels = offsets(records, kind)
        if levels:
            values = [v for _, v in levels]
            growth.append(
                f"{kind}: {', '.join(number(v, 2) for v in values)} m at "
                f"{', '.join(_level(lv) for lv, _ in levels)} {unit} "
                f"({'grows' if rising(values) else 'does not grow'} with the level)")
    if growth:
        lines += ["", "Median largest offset per level, " + "; ".join(growth) + "."]
    elsewhere = [r for r in same if scored(r) and (largest_turn(r) or 0.0) > ELSEWHERE_DEG]
    if elsewhere:
        lines += ["", f"Same-place maps whose largest offset comes from a region turned by more "
                      f"than {ELSEWHERE_DEG:.0f} degrees (a region that fits walls elsewhere, "
                      "not one moved back into place): " + "; ".join(
                          f"{r.name}, {number(value(r, 'consistency.largest_offset_m'), 2)} m "
                          f"turned {largest_turn(r):.0f} degrees"
                          + ("" if r.displacement_m is None else
                             f" (walls moved up to {number(r.displacement_m, 2)} m)")
                          for r in elsewhere) + "."]
    lines += ["", "### ROC of the confidence: share accepted at each threshold", "",
              roc_table(records, names), ""]
    lines += [f"The verdict as the accept rule scores {100 * _share(same):.0f} % of the "
              f"same-place pairs ({sum(scored(r) for r in same)} of {len(same)}, "
              f"{sum(r.alignment.get('verdict') == INCONSISTENT for r in same)} of them as "
              f"\"{INCONSISTENT}\") and {100 * _share(other):.0f} % of the other-place pairs "
              f"({sum(scored(r) for r in other)} of {len(other)}); the confidence alone at "
              f"{CURRENT} accepts {sum(accepted(r, CURRENT) for r in same)} and "
              f"{sum(accepted(r, CURRENT) for r in other)}."]
    s = safe(records)
    if s is not None:
        lines += ["", f"The lowest confidence threshold that accepts no other-place pair, "
                      f"{s.threshold:.2f}, accepts {100 * s.same:.0f} % of the same-place pairs "
                      f"({sum(accepted(r, s.threshold) for r in same)} of {len(same)})."]
    if other:
        top = max(other, key=lambda r: value(r, "confidence") or 0.0)
        lines += ["", f"Worst other-place pair: {describe(top)}."]
    refused = [r for r in same if not scored(r)]
    let_in = [r for r in other if scored(r)]
    lines += ["", "### Pairs that go wrong", "",
              f"Same place refused (\"{OTHER}\"): {len(refused)} of {len(same)}"
              + (":" if refused else "."), *(wrong_line(r) for r in refused), "",
              f"Another place scored: {len(let_in)} of {len(other)}"
              + (":" if let_in else "."), *(wrong_line(r) for r in let_in)]
    wrong = pose_wrong(records)
    known = [r for r in same if r.pose_error_m is not None]
    lines += ["", f"Poses off by more than 1 m or 5 degrees at the truth's centre: {len(wrong)} "
                  f"of the {len(known)} same-place pairs with a known pose (for a bent, broken or "
                  "drifted map the known pose is that of the map before it was distorted)"
                  + (":" if wrong else ".")]
    lines += [f"- {r.name}: {number(r.pose_error_m, 2)} m, {number(r.yaw_error_deg, 1)} deg, "
              f"confidence {number(value(r, 'confidence'), 2)}" for r in wrong]
    failed = [r for r in everything if r.error]
    if failed:
        lines += ["", "Failed runs:", *(f"- {r.name}: {r.error}" for r in failed)]
    return "\n".join(lines)


def _share(records: list[Record]) -> float:
    """The share of the records the verdict scores."""
    return sum(scored(r) for r in records) / len(records) if records else 0.0


def cases(data: Path) -> list[Case]:
    """None: the corpus keeps no stored references (its records are in :data:`RECORDS`)."""
    return []


def section(data: Path, record: Figures) -> Section:
    """The corpus measured (records written to :data:`RECORDS` as they come) and its section
    of docs/validation.md."""
    start = time.perf_counter()
    records = run(pairs(data), RECORDS)
    print(f"corpus: records in {RECORDS}", file=sys.stderr, flush=True)
    return Section(markdown(records, seconds=time.perf_counter() - start))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.validation.corpus",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" / "corpus.jsonl",
                        help="JSON lines written as the pairs are measured (default: %(default)s)")
    parser.add_argument("--data", type=Path, default=DATA,
                        help="the shared data folder (default: %(default)s)")
    parser.add_argument("--only", default=None,
                        help="only the pairs whose name contains this text")
    parser.add_argument("--fields", default="confidence",
                        help="figures of the ROC, comma-separated (default: %(default)s)")
    parser.add_argument("--records", type=Path, default=None,
                        help="analyse the records of this file instead of running the corpus")
    parser.add_argument("--list", action="store_true", help="list the pairs; run nothing")
    args = parser.parse_args(argv)
    chosen = [p for p in pairs(args.data) if args.only is None or args.only in p.name]
    if args.list:
        for p in chosen:
            print(f"{p.name}\t{p.kind}\t{_level(p.level)}\t{'same' if p.same else 'other'}")
        return 0
    if args.records is not None:
        records = load(args.records)
    else:
        if not args.data.is_dir():
            print(f"{args.data}: absent: synthetic pairs only", file=sys.stderr)

        def say(r: Record) -> None:
            what = (f"dropped (shares {number(r.shared_walls, 2)} of its walls)" if r.dropped
                    else f"confidence {number(value(r, 'confidence'), 2)}, "
                         f"{r.alignment.get('verdict')}")
            print(f"{r.name}: {what}, {r.build_seconds + r.seconds:.1f} s"
                  + (f" ({r.error})" if r.error else ""), file=sys.stderr, flush=True)

        start = time.perf_counter()
        records = run(chosen, args.out, say)
        print(f"{len(records)} pairs in {time.perf_counter() - start:.0f} s; records in "
              f"{args.out}", file=sys.stderr)
    print(markdown(records, tuple(args.fields.split(","))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
