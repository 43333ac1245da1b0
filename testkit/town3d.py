"""A town of blocks in 3D, as a mobile mapper's map holds it (issue 57): the truth, and the same
town mapped again with another draw of the points and a drift, as the map. Metres, z up.

The town: ``columns`` x ``rows`` blocks of PITCH metres, each a building of its own size and
height (facades with doorways set back, no roof: the street's view), the street's ground around
it, poles and parked cars (boxes) along its kerbs; every surface sampled uniformly at random,
``points`` points in all, with NOISE metres of Gaussian noise. The layout is one seed; the
truth and the map draw their points with two others. The map is bent as a drifting odometry
bends it (its far end lowered by DRIFT_Z and moved sideways by DRIFT_Y, growing with the square
of the distance along x) and given in its own frame: turned by YAW about z and shifted by SHIFT.

Its blocks are alike: at 3 x 3 blocks the FPFH features of the global 3D search match too few
right pairs for its RANSAC, which returns a wrong pose (the plans' second guess,
:mod:`pcmapq.align.plan_guess`, is what registers it). ``bench/large_3d.py`` writes it large.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

#: The noise of each axis, metres.
NOISE = 0.01
#: A block's side (building and its street), metres, and the town's blocks along x and y.
PITCH, COLUMNS, ROWS = 36.0, 3, 2
#: The map's drift at the town's far end (x), metres: down, and sideways.
DRIFT_Z, DRIFT_Y = 0.15, 0.10
#: The map's frame: p_map = R_z(YAW) p_bent + SHIFT.
YAW, SHIFT = math.radians(25.0), np.array([12.0, -7.0, 1.5])
#: The seeds of the layout, the truth's points and the map's points.
LAYOUT_SEED, TRUTH_SEED, MAP_SEED = 0, 1, 2


@dataclass(frozen=True)
class Rect:
    """An axis-aligned rectangle: normal along ``axis`` at ``at``; ``lo``/``hi`` its extent on
    the two other axes in axis order; ``holes``: rectangles (lo, hi) left without points."""

    axis: int
    at: float
    lo: tuple[float, float]
    hi: tuple[float, float]
    holes: tuple[tuple[tuple[float, float], tuple[float, float]], ...] = ()

    @property
    def area(self) -> float:
        whole = (self.hi[0] - self.lo[0]) * (self.hi[1] - self.lo[1])
        return whole - sum((h[0] - lo[0]) * (h[1] - lo[1]) for lo, h in self.holes)

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """``n`` points (n, 3) uniform on the rectangle outside its holes."""
        out = np.empty((0, 2))
        while len(out) < n:
            uv = rng.uniform(self.lo, self.hi, size=(int((n - len(out)) * 1.2) + 16, 2))
            hit = np.zeros(len(uv), bool)
            for lo, hi in self.holes:
                hit |= np.all((uv >= lo) & (uv <= hi), axis=1)
            out = np.vstack([out, uv[~hit]])
        pts = np.empty((n, 3))
        pts[:, self.axis] = self.at
        pts[:, [a for a in range(3) if a != self.axis]] = out[:n]
        return pts


@dataclass(frozen=True)
class Pole:
    """A vertical cylinder: centre (x, y), radius and height, metres."""

    x: float
    y: float
    radius: float
    height: float

    @property
    def area(self) -> float:
        return 2 * math.pi * self.radius * self.height

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        turn = rng.uniform(0.0, 2 * math.pi, n)
        return np.column_stack([self.x + self.radius * np.cos(turn),
                                self.y + self.radius * np.sin(turn),
                                rng.uniform(0.0, self.height, n)])


def facade(axis: int, at: float, start: float, stop: float, height: float, inward: float,
           rng: np.random.Generator) -> list[Rect]:
    """A facade at ``axis`` = ``at`` from ``start`` to ``stop`` along the other plan axis, with
    doorways (1.5 m wide, 2.4 m high) set back 0.5 m (``inward``: +1 or -1, the building's
    side) every 4 to 9 m: the wall with holes, and each doorway's back, jambs and lintel."""
    doors = start + np.cumsum(rng.uniform(4.0, 9.0, int((stop - start) / 4) + 1))
    doors = doors[doors < stop - 2.0]
    near, far = sorted((at, at + 0.5 * inward))
    parts = []
    for d in map(float, doors):
        lintel = ((near, d), (far, d + 1.5)) if axis == 0 else ((d, near), (d + 1.5, far))
        parts += [Rect(axis, at + 0.5 * inward, (d, 0.0), (d + 1.5, 2.4)),
                  Rect(1 - axis, d, (near, 0.0), (far, 2.4)),
                  Rect(1 - axis, d + 1.5, (near, 0.0), (far, 2.4)),
                  Rect(2, 2.4, *lintel)]
    holes = tuple(((float(d), 0.0), (float(d) + 1.5, 2.4)) for d in doors)
    return [Rect(axis, at, (start, 0.0), (stop, height), holes), *parts]


def block(i: int, j: int, rng: np.random.Generator) -> list[Rect | Pole]:
    """Block (i, j): its ground, its building's four facades, its poles and cars."""
    x0, y0 = i * PITCH, j * PITCH
    w, d, h = rng.uniform(18.0, 26.0), rng.uniform(18.0, 26.0), rng.uniform(6.0, 16.0)
    bx, by = x0 + rng.uniform(4.0, PITCH - 4.0 - w), y0 + rng.uniform(4.0, PITCH - 4.0 - d)
    parts: list[Rect | Pole] = [Rect(2, 0.0, (x0, y0), (x0 + PITCH, y0 + PITCH),
                                     (((bx, by), (bx + w, by + d)),))]
    parts += facade(1, by, bx, bx + w, h, 1.0, rng) + facade(1, by + d, bx, bx + w, h, -1.0, rng)
    parts += facade(0, bx, by, by + d, h, 1.0, rng) + facade(0, bx + w, by, by + d, h, -1.0, rng)
    for _ in range(rng.integers(2, 5)):
        px, py = rng.uniform(x0 + 1.0, x0 + PITCH - 1.0), y0 + rng.choice([1.5, PITCH - 1.5])
        if not (bx - 0.5 < px < bx + w + 0.5 and by - 0.5 < py < by + d + 0.5):
            parts.append(Pole(px, py, 0.12, rng.uniform(4.0, 7.0)))
    for _ in range(rng.integers(1, 4)):  # a car by the kerb: its top and four sides
        cx, cy = rng.uniform(x0 + 1.0, x0 + PITCH - 6.0), y0 + rng.choice([2.2, PITCH - 4.0])
        if bx - 1.0 < cx + 4.2 and cx < bx + w + 1.0 and by - 1.0 < cy + 1.8 and cy < by + d + 1.0:
            continue
        parts += [Rect(2, 1.5, (cx, cy), (cx + 4.2, cy + 1.8)),
                  *(Rect(0, x, (cy, 0.0), (cy + 1.8, 1.5)) for x in (cx, cx + 4.2)),
                  *(Rect(1, y, (cx, 0.0), (cx + 4.2, 1.5)) for y in (cy, cy + 1.8))]
    return parts


def town(columns: int = COLUMNS, rows: int = ROWS) -> list[list[Rect | Pole]]:
    """The town's blocks, each a list of surfaces."""
    rng = np.random.default_rng(LAYOUT_SEED)
    return [block(i, j, rng) for j in range(rows) for i in range(columns)]


def bent(points: np.ndarray, length: float) -> np.ndarray:
    """The map's drift applied to truth points (n, 3): lowered by DRIFT_Z and moved along y by
    DRIFT_Y times (x / length)^2, then put in the map's frame (YAW, SHIFT)."""
    out = points.copy()
    share = np.clip(points[:, 0] / length, 0.0, None) ** 2
    out[:, 1] += DRIFT_Y * share
    out[:, 2] -= DRIFT_Z * share
    c, s = math.cos(YAW), math.sin(YAW)
    out[:, :2] = out[:, :2] @ np.array([[c, s], [-s, c]])
    return out + SHIFT


def clouds(points: int, seed: int, as_map: bool, columns: int = COLUMNS,
           rows: int = ROWS) -> Iterator[np.ndarray]:
    """Yield the cloud block by block, (n_k, 3) float32, ``points`` points in all: the truth,
    or (``as_map``) the map in its frame."""
    blocks = town(columns, rows)
    flat = [s for b in blocks for s in b]
    rng = np.random.default_rng(seed)
    areas = np.array([s.area for s in flat])
    counts = iter(rng.multinomial(points, areas / areas.sum()))
    length = max(s.lo[0] + PITCH for s in flat if isinstance(s, Rect) and s.axis == 2
                 and s.at == 0.0)
    for surfaces in blocks:
        part = np.vstack([s.sample(next(counts), rng) for s in surfaces])
        part += rng.normal(0.0, NOISE, part.shape)
        yield (bent(part, length) if as_map else part).astype("<f4")


def pair(points: int, columns: int = COLUMNS, rows: int = ROWS) -> tuple[np.ndarray, np.ndarray]:
    """The map and the truth, (``points``, 3) float32 each, in memory."""
    return tuple(np.vstack(list(clouds(points, seed, as_map, columns, rows)))
                 for seed, as_map in ((MAP_SEED, True), (TRUTH_SEED, False)))


def map_to_truth() -> np.ndarray:
    """4x4 transform that takes the map's frame back to the truth's, drift aside."""
    c, s = math.cos(YAW), math.sin(YAW)
    out = np.eye(4)
    out[:2, :2] = [[c, s], [-s, c]]
    out[:3, 3] = -out[:3, :3] @ SHIFT
    return out
