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
other's plan); synthetic plan i against plan j (i in 0-4, j = i + 1 and i + 2 modulo 5, points
and images); each degradation's strongest level of plan i against plan (i + 1) mod 3.

Every map and truth is built lazily (a callable given a scratch folder) and deterministically
(seeded). ``run`` scores the pairs; ``roc``, ``acceptance`` and ``markdown`` analyse them.

    python -m bench.validation.corpus --out bench/results/corpus.jsonl [--data DIR]
        [--only TEXT] [--fields confidence,truth_recall] [--records FILE]
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
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np

from pcmapq import synth
from pcmapq.config import Settings
from pcmapq.io import PointMap
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.io.writers import write_ros_map
from pcmapq.pipeline import evaluate
from pcmapq.raster.draw import points_to_grid, polygon_cells
from pcmapq.report.text import number
from pcmapq.transform import Similarity2D

from . import drift, same_place
from .common import DATA, ROOT, Section, header, row
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
    "drift": "drift (gain error), %",
    "drift full log": "drift (gain error), %",
    "other carmen": "",
    "other halmstad": "",
    "other floor plans": "",
    "other synthetic": "",
    "other degraded": "degradation",
}
#: Other places made of synthetic plans (plan i against plan j).
SYNTHETIC_OTHER = ("other synthetic", "other degraded")
#: The degradation ladders (a table each).
LADDERS = ("noise", "missing walls", "bend", "clutter", "broken half", "drift")

@dataclass(frozen=True)
class Pair:
    """A map and a truth, labelled. name: unique; kind: a key of :data:`KINDS`; level: the
    ladder's level (its unit in KINDS), or a label, None when clean; same: whether the map shows
    the truth's place; form: 'points', 'image', 'log' or 'real'; build_map / build_truth: given
    a scratch folder, the map (a path or a PointMap) and the truth's path, built on demand and
    deterministic; known: p_truth = known(p_map) where known (for a degraded map: the frame of
    the map before it was degraded); note: what else the level means (or how to say it, read
    when the pair is measured)."""

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


@dataclass
class Record:
    """One pair's result: its labels, the whole "alignment" block of ``Result.to_dict()``
    (fitness, truth recall, agreement, distinctiveness, confidence, a verdict where there is
    one), the coverage, the "consistency" block where there is one, the pose error against
    the known transform at the truth's centre (metres, degrees; None where unknown), seconds
    to build the map and truth and to evaluate, and the error if the run failed."""

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


def truth_plan(seed: int) -> Callable[[Path], Path]:
    """Plan ``seed`` rendered in its own frame (the truth of every synthetic pair), written once
    per scratch folder."""
    def build(folder: Path) -> Path:
        path = folder / f"truth-plan-{seed}.png"
        if not path.exists():
            draw(synth.building_plan(seed), path)
        return path
    return build


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


def synthetic_map(form: str, seed: int, kind: str | None = None, level: float = 0.0,
                  name: str = "") -> Callable[[Path], Path | PointMap]:
    """Plan ``seed`` (degraded by ``kind`` at ``level`` when given) in its map frame
    :func:`frame`, as points or as an image."""
    def build(folder: Path) -> Path | PointMap:
        plan = synth.building_plan(seed)
        segments, noise = (plan, 0.0) if kind is None else degrade(kind, level, plan, seed)
        in_map = synth.transform_segments(segments, frame(seed).inverse())
        if form == "points":
            return cloud(in_map, name, noise, seed)
        return draw(in_map, folder / f"{slug(name)}.png", noise, seed)
    return build


def bend_note(displacement: float) -> str:
    """What a bend level means: its rate and how far the plan's far end moves."""
    k = BENDS[displacement]
    plan = synth.building_plan(0)
    fine = synth.densify(plan, 0.1).reshape(-1, 2)
    moved = float(np.max(np.linalg.norm(synth.bend(fine, k) - fine, axis=1)))
    bottom = 2 * WIDTH * math.sin(math.radians(k * WIDTH) / 2)
    return (f"{k:.4f} deg/m: far corner moves {moved:.2f} m, far end of the bottom wall "
            f"{bottom:.2f} m")


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


def drift_note(log: Path, level: float) -> str:
    """The drifted trajectory's largest position and heading errors (unaligned)."""
    poses = _log(log)[0]
    moved = drift.drifted(poses, level, DRIFT_SEED)
    metres = float(np.max(np.linalg.norm(moved[:, :2] - poses[:, :2], axis=1)))
    degrees = float(np.degrees(np.max(np.abs(drift.wrap(moved[:, 2] - poses[:, 2])))))
    return (f"{log.name.split('-corrected')[0]}: trajectory off by up to {metres:.1f} m and "
            f"{degrees:.1f} deg")


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
    drifts = {f"{log} drifted {100 * level:g} % vs corrected": level
              for log, level in same_place.DRIFTS}
    x, y, yaw = SAMPLE_POSE
    for p in same_place.pairs(data):
        if p.name == "sample scan vs its plan":
            kind, level, form = "sample", None, "points"
        elif p.name in drifts:
            kind, level, form = "drift full log", 100 * drifts[p.name], "log"
        elif p.same:
            kind, level, form = "real", None, "real"
        else:
            kind, level, form = _other_kind(p.name), None, "real"
        known = (Similarity2D(x, y, math.radians(yaw)) if kind == "sample" else
                 Similarity2D() if kind == "drift full log" else None)
        yield Pair(f"{kind}: {p.name}", kind, level, p.same, form, _source(p.map_source),
                   _fixed(p.truth), p.settings, known)


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
                               known=frame(s), note=note)
    n = len(CLEAN_SEEDS)
    for form in ("points", "image"):
        for i in CLEAN_SEEDS:
            for j in ((i + 1) % n, (i + 2) % n):
                name = f"other synthetic {form}: plan {i} vs plan {j}"
                yield Pair(name, "other synthetic", None, False, form,
                           synthetic_map(form, i, name=name), truth_plan(j))
    for kind, levels in ladders.items():
        for form in ("points", "image"):
            for i in LADDER_SEEDS:
                j = (i + 1) % len(LADDER_SEEDS)
                name = f"other degraded {form}: plan {i} {kind} {levels[-1]:g} vs plan {j}"
                yield Pair(name, "other degraded", f"{kind} {levels[-1]:g}", False, form,
                           synthetic_map(form, i, kind, levels[-1], name), truth_plan(j))


def drift_pairs(data: Path) -> Iterator[Pair]:
    """CARMEN maps from drifted poses against the corrected map of the same scans."""
    for log in DRIFT_LOGS:
        path = same_place.carmen(data, log)
        for level in DRIFT_LEVELS:
            name = f"drift {log} {100 * level:g} %"
            yield Pair(name, "drift", 100 * level, True, "log", drift_map(path, level, name),
                       drift_truth(path), known=Similarity2D(),
                       note=lambda path=path, level=level: drift_note(path, level))


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
    (coverage, pose_error_m, ...), or a dotted path ('consistency.worst_m'). None when absent
    or not a number (a failed run has none)."""
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


# ---- markdown --------------------------------------------------------------------------------

def _level(level: float | str | None) -> str:
    return "-" if level is None else f"{level:g}" if isinstance(level, int | float) else level


def _range(group: Group) -> str:
    if group.low is None or group.high is None:
        return "-"
    lo, hi = number(group.low, 2), number(group.high, 2)
    return lo if lo == hi else f"{lo}-{hi}"


def ladder_table(groups: list[Group], kind: str, name: str = "confidence") -> str:
    """One ladder: per form and level, pairs, share accepted, median and range of the figure."""
    lines = [header([KINDS[kind] or "level", "form", "pairs", f"accepted at {CURRENT}",
                     f"median {name}", "range"])]
    for g in sorted((g for g in groups if g.kind == kind),
                    key=lambda g: (_order(g.level), g.form)):
        lines.append(row([_level(g.level), g.form, str(g.pairs),
                          f"{g.accepted} ({100 * g.share:.0f} %)", number(g.median, 2),
                          _range(g)]))
    return "\n".join(lines)


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


def verdict_table(records: list[Record]) -> str:
    """How many pairs of each kind got each verdict (where the result has one)."""
    names = list(dict.fromkeys(str(r.alignment.get("verdict")) for r in records))
    counts: dict[tuple[str, bool], dict[str, int]] = {}
    for r in records:
        tally = counts.setdefault((r.kind, r.same), dict.fromkeys(names, 0))
        tally[str(r.alignment.get("verdict"))] += 1
    kinds = list(KINDS)
    lines = [header(["kind", "place", *names])]
    for (kind, same), tally in sorted(counts.items(), key=lambda kv: (
            not kv[0][1], kinds.index(kv[0][0]) if kv[0][0] in kinds else len(kinds))):
        lines.append(row([kind, "same" if same else "other", *(str(tally[n]) for n in names)]))
    return "\n".join(lines)


def describe(r: Record) -> str:
    """'name (confidence c, distinctiveness d, recall r, fitness f)'."""
    a = r.alignment
    return (f"{r.name} (confidence {number(a.get('confidence'), 2)}, distinctiveness "
            f"{number(a.get('distinctiveness'), 2)}, truth recall "
            f"{number(a.get('truth_recall'), 2)}, fitness {number(a.get('fitness'), 2)})")


def markdown(records: list[Record], names: tuple[str, ...] = ("confidence",)) -> str:
    """The corpus's section: what it holds, a table per ladder, the other places, the ROC, the
    worst other-place pair, wrong poses and failures."""
    same = [r for r in records if r.same]
    other = [r for r in records if not r.same]
    groups = acceptance(records)
    kinds: dict[str, int] = {}
    for r in records:
        kinds[r.kind] = kinds.get(r.kind, 0) + 1
    seconds = sum(r.seconds + r.build_seconds for r in records)
    lines = [
        "## Same place or another place: a labelled corpus", "",
        f"{len(records)} pairs ({len(same)} of the truth's place, {len(other)} of another), "
        "scored with `force` and no detectors (`python -m bench.validation.corpus`; "
        "`bench/validation/corpus.py` says how each is made): "
        + ", ".join(f"{k} {n}" for k, n in kinds.items())
        + f". Today a map is refused below confidence {CURRENT}. {seconds:.0f} s in all.", "",
        "### Clean maps of the truth's place",
    ]
    for kind in ("clean", "sample", "real"):
        if any(g.kind == kind for g in groups):
            lines += ["", f"{kind}:", "", ladder_table(groups, kind)]
    for kind in (*LADDERS, "drift full log"):
        if any(g.kind == kind for g in groups):
            notes = list(dict.fromkeys(f"{_level(r.level)} %: {r.note}" if "drift" in kind
                                       else f"{_level(r.level)}: {r.note}" for r in records
                                       if r.kind == kind and r.note))
            lines += ["", f"### {kind}", "", ladder_table(groups, kind)]
            lines += ["", "; ".join(notes) + "."] if notes else []
    lines += ["", "### Another place", ""]
    rows = [header(["kind", "form", "level", "pairs", f"accepted at {CURRENT}",
                    "median confidence", "range"])]
    for g in groups:
        if not g.same:
            rows.append(row([g.kind, g.form, _level(g.level), str(g.pairs),
                             f"{g.accepted} ({100 * g.share:.0f} %)", number(g.median, 2),
                             _range(g)]))
    lines += ["\n".join(rows), "", "### ROC: share accepted at each threshold", "",
              roc_table(records, names)]
    real = [r for r in records if r.kind not in SYNTHETIC_OTHER]
    if len(real) < len(records) and any(not r.same for r in real):
        lines += ["", "The same without the synthetic other places (plan i against plan j: "
                      "the plans share their outer walls, corridor, L-shaped wall and pillars, "
                      "most of their walls):", "", roc_table(real, names)]
    if any("verdict" in r.alignment for r in records):
        lines += ["", "### Verdicts (`alignment.verdict`) by kind", "", verdict_table(records)]
    if other:
        top = max(other, key=lambda r: value(r, "confidence") or 0.0)
        lines += ["", f"Worst other-place pair: {describe(top)}."]
    s = safe(records)
    if s is not None:
        lines += ["", f"The lowest confidence threshold that accepts no other-place pair, "
                      f"{s.threshold:.2f}, accepts {100 * s.same:.0f} % of the same-place pairs "
                      f"({sum(accepted(r, s.threshold) for r in same)} of {len(same)}); "
                      f"{CURRENT} accepts {sum(accepted(r, CURRENT) for r in same)} of them and "
                      f"{sum(accepted(r, CURRENT) for r in other)} of the {len(other)} "
                      "other-place pairs."]
    wrong = pose_wrong(records)
    known = [r for r in same if r.pose_error_m is not None]
    lines += ["", f"Poses off by more than 1 m or 5 degrees at the truth's centre: {len(wrong)} "
                  f"of the {len(known)} same-place pairs with a known pose (for a bent, broken or "
                  "drifted map the known pose is that of the map before it was distorted)"
                  + (":" if wrong else ".")]
    lines += [f"- {r.name}: {number(r.pose_error_m, 2)} m, {number(r.yaw_error_deg, 1)} deg, "
              f"confidence {number(value(r, 'confidence'), 2)}" for r in wrong]
    failed = [r for r in records if r.error]
    if failed:
        lines += ["", "Failed runs:", *(f"- {r.name}: {r.error}" for r in failed)]
    return "\n".join(lines)


def section(data: Path, record: Figures) -> Section:
    """The corpus measured and its section (for docs/validation.md, not wired in)."""
    records = run(pairs(data))
    for r in records:
        record[f"corpus-{r.name}"] = r.summary()
    return Section(markdown(records))


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
            print(f"{r.name}: confidence {number(value(r, 'confidence'), 2)}, "
                  f"{r.build_seconds + r.seconds:.1f} s" + (f" ({r.error})" if r.error else ""),
                  file=sys.stderr, flush=True)

        start = time.perf_counter()
        records = run(chosen, args.out, say)
        print(f"{len(records)} pairs in {time.perf_counter() - start:.0f} s; records in "
              f"{args.out}", file=sys.stderr)
    print(markdown(records, tuple(args.fields.split(","))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
