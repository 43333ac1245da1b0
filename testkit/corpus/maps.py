"""The corpus's synthetic places and maps: building plans (``synth.building_plan``) of the
usual 24 x 16 m size and of other outlines, and the round rooms, each drawn as an image or
sampled as points in a known map frame, degraded by a ladder's level (wall noise, missing
walls, a bend, clutter, a broken half, a doubled half, a partial view); and the screening of
two layouts for the walls they share."""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from scipy.spatial import cKDTree

from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import PointMap
from pcmapq.io.writers import write_ros_map
from pcmapq.raster.draw import points_to_grid, polygon_cells

from .. import synth
from ..realdata.same_place import RIGID

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
#: A doubled half: the right half drawn a second time this many metres up (a SLAM map that
#: closed no loop drew it twice); a partial view: the share of the plan's width kept, from
#: its left side (a robot that saw part of the building).
DOUBLED = (0.5, 1.0, 2.0)
PARTIAL = (0.6, 0.45, 0.3)


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


def bend_rate(displacement: float) -> float:
    """Degrees per metre of ``synth.bend`` (pivot at the origin) that move the plan's far corner
    (WIDTH, HEIGHT) by ``displacement`` metres: the corner turns by k * WIDTH degrees about the
    origin, a chord of 2 r sin(angle / 2), r = |(WIDTH, HEIGHT)|."""
    r = math.hypot(WIDTH, HEIGHT)
    return math.degrees(2.0 * math.asin(displacement / (2.0 * r))) / WIDTH


#: Far-corner displacement (m) -> degrees per metre: 0.2 -> 0.0166, 0.5 -> 0.0414, 1.0 -> 0.0828.
BENDS = {d: bend_rate(d) for d in BEND}


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


def doubled(segments: np.ndarray, offset: float) -> np.ndarray:
    """The plan with its right half (pieces of at most 0.1 m whose middle lies right of
    WIDTH / 2) drawn a second time, ``offset`` metres up: a map that drew a stretch twice."""
    fine = synth.densify(segments, 0.1)
    right = fine[(fine[:, 0] + fine[:, 2]) / 2 > WIDTH / 2]
    return np.vstack([fine, right + np.array([0.0, offset, 0.0, offset])])


def partial(segments: np.ndarray, share: float) -> np.ndarray:
    """The pieces of the plan (at most 0.1 m) whose middle lies in the left ``share`` of its
    width: a map of part of the building."""
    fine = synth.densify(segments, 0.1)
    return fine[(fine[:, 0] + fine[:, 2]) / 2 <= share * WIDTH]


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
    if kind == "doubled half":
        return doubled(segments, float(level)), 0.0
    if kind == "partial view":
        return partial(segments, float(level)), 0.0
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
    the bend and the broken half (the plan's far corner); the offset of a doubled half; 0 where
    walls are dropped, cut off or boxes added."""
    if kind in ("noise", "doubled half"):
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


def slug(name: str) -> str:
    """A pair's name as a file name."""
    return re.sub(r"[^a-z0-9.]+", "-", name.lower()).strip("-")
