"""The corpus's pairs, each labelled: same place or not, a kind (clean, a degradation ladder,
which other place) and a level on that ladder; the synthetic pairs, the real ones
(:mod:`testkit.realdata.same_place`) and the CARMEN drift ladders."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import lru_cache, partial
from pathlib import Path

import numpy as np

from pcmapq.core.transform import Similarity2D
from pcmapq.io import PointMap
from pcmapq.io.carmen import DEFAULT_MAX_RANGE, endpoints, read_flaser
from pcmapq.settings import Settings

from .. import drift
from ..paths import SHARED_DATA
from ..realdata import same_place
from .maps import (
    BEND,
    BROKEN,
    CLUTTER,
    DOUBLED,
    MISSING,
    NOISE,
    OTHER_SEED,
    OTHER_SIZES,
    PARTIAL,
    Layout,
    bend_note,
    frame,
    moved,
    synthetic_map,
    truth_layout,
    truth_plan,
)

#: Settings of every synthetic and CARMEN pair: both metric, forced, no detectors.
RIGID = same_place.RIGID
#: Today's rule: refused below this confidence.
CURRENT = same_place.NEW_MIN_CONFIDENCE
#: Plan seeds of the clean synthetic pairs, and of the degradation ladders.
CLEAN_SEEDS = (0, 1, 2, 3, 4)
LADDER_SEEDS = (0, 1, 2)
#: CARMEN drift: logs, levels (relative gain errors), scans used, seed.
DRIFT_LOGS = ("intel", "fhw", "aces")
DRIFT_LEVELS = (0.01, 0.02, 0.03, 0.04)
DRIFT_SCANS = 200
DRIFT_SEED = 0
#: The shipped sample's pose (tools/make_sample.py's SCAN_POSE): x, y metres, yaw degrees.
SAMPLE_POSE = (6.0, 8.0, 37.0)


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
    "doubled half": "right half drawn again, offset m",
    "partial view": "share of the plan's width kept",
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
LADDERS = ("noise", "missing walls", "bend", "clutter", "broken half", "doubled half",
           "partial view", "drift")


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
                                 "clutter": CLUTTER, "broken half": BROKEN,
                                 "doubled half": DOUBLED, "partial view": PARTIAL}
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


def pairs(data: Path = SHARED_DATA) -> list[Pair]:
    """The whole corpus: synthetic pairs always; the real ones where ``data`` holds them."""
    out = list(synthetic_pairs())
    if data.is_dir():
        out[:0] = list(real_pairs(data)) + list(drift_pairs(data))
    return out
