"""A synthetic 3D building of known planes: two rooms side by side (walls, floor, ceiling; a
wall between them thicker than twice the structures' line margin and no door, so that each
room's floor, ceiling and the lines where they meet its walls are pieces of their own), a
free-standing box of furniture in each, every face sampled as a LiDAR map of the
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
#: Where room B starts and ends along x, metres: the wall between the rooms is 0.5 m thick.
B_START, B_END = 6.5, 10.5
#: Room A's box: x0, x1, y0, y1 and its top, metres.
A_BOX = (1.5, 3.5, 1.5, 3.1, 1.0)
#: The cabinet the furnished map adds to room A, 1.2 x 1.5 x 1.0 m (its faces 1.2 m^2 or more),
#: 0.5 m or more from every other face: x0, x1, y0, y1 and its top, metres.
CABINET = (4.3, 5.5, 0.8, 2.3, 1.0)
#: The moved map's changes: each changed face's shift along its normal's axis, metres.
MOVED = {"B.wall.x1": 0.3, "A.floor": 0.05}
#: The furnished map's: room A's box 0.2 m along +x moves its x faces along their normal (its
#: top and y faces slide in their planes), and the cabinet is new.
FURNISHED = {"A.box.x0": 0.2, "A.box.x1": 0.2}


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


def faces(b_end: float = B_END, a_box_shift: float = 0.0, cabinet: bool = False
          ) -> list[Face]:
    """The building: room A (6 x 5 m) and room B (from x = :data:`B_START` to ``b_end``, 5 m
    wide) either side of a 0.5 m wall, a 2.0 x 1.6 x 1.0 m box in A (every face over 1.5 m^2;
    ``a_box_shift`` metres further along +x) and a 1.5 x 1.5 x 0.3 m one in B (its top
    2.25 m^2, its sides 0.45 m^2); ``cabinet``: with :data:`CABINET` in room A too. No floor
    under a box."""
    x0, x1, y0, y1, top = A_BOX
    boxes = [("A.box", x0 + a_box_shift, x1 + a_box_shift, y0, y1, top)]
    if cabinet:
        boxes.append(("A.cabinet", *CABINET))
    under = tuple(((bx0, by0), (bx1, by1)) for _, bx0, bx1, by0, by1, _ in boxes)
    return [*room("A", 0.0, 6.0, 0.0, 5.0, under),
            *room("B", B_START, b_end, 0.0, 5.0, (((7.5, 2.0), (9.0, 3.5)),)),
            *(f for b in boxes for f in box(*b)), *box("B.box", 7.5, 9.0, 2.0, 3.5, 0.3)]


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
    return cloud(changed(faces(b_end=B_END + 0.3), {"A.floor": 0.05}), seed=seed)


def furnished_map(seed: int = 2) -> np.ndarray:
    """The building's map with room A's box 0.2 m further along +x and a new cabinet in room A
    (:data:`CABINET`), another draw of the noise."""
    return cloud(faces(a_box_shift=0.2, cabinet=True), seed=seed)


def planes_of(parts: list[Face]):
    """The faces as exact planes, in their order (a
    :class:`~pcmapq.features.planes3d.Planes`): normals along their axes, offsets their
    places, corners their rectangles (the first edge along the longer side), no noise."""
    from pcmapq.features.planes3d import Planes

    corners = np.zeros((len(parts), 4, 3))
    extent = np.zeros((len(parts), 2))
    for k, f in enumerate(parts):
        other = [a for a in range(3) if a != f.axis]
        (u0, v0), (u1, v1) = f.lo, f.hi
        uv = [[u0, v0], [u1, v0], [u1, v1], [u0, v1]]
        if v1 - v0 > u1 - u0:  # the longer side first
            uv = [[u0, v0], [u0, v1], [u1, v1], [u1, v0]]
        corners[k][:, f.axis] = f.at
        corners[k][:, other] = uv
        extent[k] = sorted((u1 - u0, v1 - v0), reverse=True)
    return Planes(np.eye(3)[[f.axis for f in parts]], np.array([f.at for f in parts]),
                  corners.mean(axis=1), corners, extent, np.array([f.area for f in parts]),
                  np.full(len(parts), 100, dtype=np.int64))


def face_names(normal: np.ndarray, point: np.ndarray, parts: list[Face] | None = None,
               near: float = 0.1, margin: float = 0.25) -> list[str]:
    """The faces (of ``parts``, the building's by default) a plane lies on, sorted: those
    whose axis is that of the largest component of its ``normal`` (3,), within ``near``
    metres of ``point`` (3,, on the plane) along it, their rectangle grown by ``margin``
    holding it."""
    axis = int(np.argmax(np.abs(normal)))
    return sorted(f.name for f in (faces() if parts is None else parts)
                  if f.axis == axis and abs(point[axis] - f.at) <= near
                  and _holds(f, point, margin))


def _holds(face: Face, point: np.ndarray, margin: float) -> bool:
    other = [a for a in range(3) if a != face.axis]
    return bool(np.all((point[other] >= np.subtract(face.lo, margin))
                       & (point[other] <= np.add(face.hi, margin))))


def plane_name(normal: np.ndarray, centroid: np.ndarray, parts: list[Face] | None = None
               ) -> str:
    """The face a plane (its unit normal and centroid, (3,) each) lies on, ``"?"`` for
    none; ``"A|B"`` for several."""
    return "|".join(face_names(normal, centroid, parts)) or "?"


def line_name(direction: np.ndarray, point: np.ndarray, parts: list[Face] | None = None,
              near: float = 0.1, margin: float = 0.25) -> str:
    """The two faces a line (its unit direction and middle, (3,) each) lies on, joined by
    ``"+"`` (``"?"`` for none): the faces parallel to it (their axis across it), within
    ``near`` metres of its middle along their axis, their rectangles grown by ``margin``
    holding it."""
    names = sorted(f.name for f in (faces() if parts is None else parts)
                   if abs(direction[f.axis]) < 0.1 and abs(point[f.axis] - f.at) <= near
                   and _holds(f, point, margin))
    return "+".join(names) or "?"


def injected(name: str, shifts: dict[str, float]) -> float:
    """The displacement a change puts on a named structure (:func:`plane_name`,
    :func:`line_name`), metres: a plane's, its face's shift along its normal (signed); a
    line's, how far it moves across itself, the hypotenuse of its two faces' shifts."""
    parts = name.split("+")
    if len(parts) == 1:
        return shifts.get(name, 0.0)
    return float(np.hypot(*(shifts.get(p, 0.0) for p in parts[:2])))


@functools.cache
def known_structures():
    """The structures of :func:`moved_map` against the building (seed 1), both taken to be in
    the truth frame, with the default settings (a
    :class:`~pcmapq.match.structures.Structures3D`; made once)."""
    from pcmapq.evaluation.scoring import structures_3d
    from pcmapq.settings import StructuresConfig

    return structures_3d(cloud(faces(), seed=1), moved_map(), StructuresConfig())


def assert_same_matches(one, two) -> None:
    """Two :class:`~pcmapq.match.structures.Structures3D` with truth structures whose planes and
    plane lines match alike, field by field."""
    for name in ("planes", "plane_lines"):
        first, second = one.detectors[name], two.detectors[name]
        assert len(first.truth) == len(second.truth) > 0
        for field in ("truth_idx", "map_idx", "displacement", "angle"):
            np.testing.assert_array_equal(getattr(first.matching, field),
                                          getattr(second.matching, field))
