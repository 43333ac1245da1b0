"""A synthetic 3D building of known planes: two rooms side by side (walls, floor, ceiling; a
thick wall between them and no door, so that each room's floor and ceiling are pieces of their
own), a free-standing box of furniture in each, every face sampled as a LiDAR map of the
inside would hold it, with Gaussian noise. Faces can be moved along their normals or left
out, to make maps whose structures differ from the truth's by known amounts."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

#: The rooms' height, metres.
HEIGHT = 2.8
#: Points per square metre of a face (a 5 cm spacing).
DENSITY = 400.0


@dataclass(frozen=True)
class Face:
    """One rectangular face: ``axis`` its normal's axis (0 x, 1 y, 2 z), ``at`` its offset on
    that axis (metres), ``lo``/``hi`` its extent on the two other axes, in axis order (metres).
    ``name`` says which face it is (``"A.wall.x0"``, ``"B.floor"``, ``"A.box.top"``).
    ``holes``: rectangles ``(lo, hi)`` of the face no point is drawn in (a floor under a box,
    which no scan sees)."""

    name: str
    axis: int
    at: float
    lo: tuple[float, float]
    hi: tuple[float, float]
    holes: tuple[tuple[tuple[float, float], tuple[float, float]], ...] = ()

    @property
    def area(self) -> float:
        return float(np.prod(np.subtract(self.hi, self.lo)))

    def moved(self, offset: float) -> Face:
        """The face moved ``offset`` metres along its axis."""
        return Face(self.name, self.axis, self.at + offset, self.lo, self.hi, self.holes)


def room(name: str, x0: float, x1: float, y0: float, y1: float,
         under: tuple[tuple[tuple[float, float], tuple[float, float]], ...] = ()) -> list[Face]:
    """A room's inner faces: its floor (z = 0; none ``under`` its furniture), its ceiling and
    its four walls."""
    return [Face(f"{name}.floor", 2, 0.0, (x0, y0), (x1, y1), under),
            Face(f"{name}.ceiling", 2, HEIGHT, (x0, y0), (x1, y1)),
            Face(f"{name}.wall.x0", 0, x0, (y0, 0.0), (y1, HEIGHT)),
            Face(f"{name}.wall.x1", 0, x1, (y0, 0.0), (y1, HEIGHT)),
            Face(f"{name}.wall.y0", 1, y0, (x0, 0.0), (x1, HEIGHT)),
            Face(f"{name}.wall.y1", 1, y1, (x0, 0.0), (x1, HEIGHT))]


def box(name: str, x0: float, x1: float, y0: float, y1: float, top: float) -> list[Face]:
    """A box standing on the floor: its top and its four sides."""
    return [Face(f"{name}.top", 2, top, (x0, y0), (x1, y1)),
            Face(f"{name}.x0", 0, x0, (y0, 0.0), (y1, top)),
            Face(f"{name}.x1", 0, x1, (y0, 0.0), (y1, top)),
            Face(f"{name}.y0", 1, y0, (x0, 0.0), (x1, top)),
            Face(f"{name}.y1", 1, y1, (x0, 0.0), (x1, top))]


def faces(b_end: float = 10.3) -> list[Face]:
    """The building: room A (6 x 5 m) and room B (from x = 6.3 to ``b_end``, 5 m wide) either
    side of a 0.3 m wall, a 2.0 x 1.6 x 1.0 m box in A (every face over 1.5 m^2) and a
    1.5 x 1.5 x 0.3 m one in B (its top 2.25 m^2, its sides 0.45 m^2)."""
    return [*room("A", 0.0, 6.0, 0.0, 5.0, (((1.5, 1.5), (3.5, 3.1)),)),
            *room("B", 6.3, b_end, 0.0, 5.0, (((7.5, 2.0), (9.0, 3.5)),)),
            *box("A.box", 1.5, 3.5, 1.5, 3.1, 1.0), *box("B.box", 7.5, 9.0, 2.0, 3.5, 0.3)]


def sample(face: Face, rng: np.random.Generator, density: float = DENSITY) -> np.ndarray:
    """Points drawn uniformly on a face, ``density`` per square metre, none in its holes;
    (N, 3) metres."""
    n = int(round(face.area * density))
    other = [a for a in range(3) if a != face.axis]
    pts = np.empty((n, 3))
    pts[:, face.axis] = face.at
    pts[:, other] = rng.uniform(face.lo, face.hi, size=(n, 2))
    inside = np.zeros(n, dtype=bool)
    for lo, hi in face.holes:
        inside |= np.all((pts[:, other] >= lo) & (pts[:, other] <= hi), axis=1)
    return pts[~inside]


def cloud(parts: list[Face], noise: float = 0.01, seed: int = 0) -> np.ndarray:
    """Every face sampled, with Gaussian noise of std ``noise`` metres on every axis; (N, 3)
    metres, z up."""
    rng = np.random.default_rng(seed)
    pts = np.vstack([sample(f, rng) for f in parts])
    return pts + rng.normal(0.0, noise, size=pts.shape)


def changed(parts: list[Face], moved: dict[str, float] | None = None,
            removed: tuple[str, ...] = ()) -> list[Face]:
    """The faces with those named in ``moved`` moved by its offset (metres, along the axis)
    and those named in ``removed`` left out."""
    moved = moved or {}
    return [f.moved(moved.get(f.name, 0.0)) for f in parts if f.name not in removed]


def moved_map(seed: int = 2) -> np.ndarray:
    """The building's map with room B's far wall 0.3 m further (+x; room B 0.3 m longer)
    and room A's floor 0.05 m higher (+z), another draw of the noise."""
    return cloud(changed(faces(b_end=10.6), {"A.floor": 0.05}), seed=seed)


@functools.cache
def known_structures():
    """The structures of :func:`moved_map` against the building (seed 1), both taken to be in
    the truth frame, with the default settings (a
    :class:`~pcmapq.match.structures.Structures3D`; made once)."""
    from pcmapq.evaluation.scoring import structures_3d
    from pcmapq.settings import StructuresConfig

    return structures_3d(cloud(faces(), seed=1), moved_map(), StructuresConfig())
