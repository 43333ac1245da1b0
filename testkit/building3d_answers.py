"""The known answers of the synthetic building (:mod:`testkit.building3d`) read off a result's
``structures_3d`` block (its JSON, as ``pcmapq eval --json`` writes it or
``Result.to_dict()`` gives it): each matched structure named by the building's faces it lies
on, with the displacement its change injected and the one reported; the unmatched ones named
too. Metres and degrees."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from testkit import building3d as b

#: A changed structure is reported right within this of its injected displacement, metres.
WITHIN_M = 0.005
#: An unchanged one within this of 0, metres, and this many degrees (the building's 1 cm noise
#: on faces of a metre or two, found at a 0.1 m voxel).
STILL_M, STILL_DEG = 0.01, 0.5


@dataclass(frozen=True)
class Answer:
    """One matched structure: its name (:func:`~testkit.building3d.plane_name`,
    :func:`~testkit.building3d.line_name`), the displacement injected and reported (metres;
    a plane's signed along its normal, a line's >= 0) and the angle reported (degrees)."""

    name: str
    injected: float
    reported: float
    angle: float

    @property
    def changed(self) -> bool:
        return self.injected != 0.0

    @property
    def right(self) -> bool:
        """Whether the report is the known answer: a changed structure within
        :data:`WITHIN_M` of its injected displacement, an unchanged one within
        :data:`STILL_M` and :data:`STILL_DEG` of 0."""
        if self.changed:
            return abs(self.reported - self.injected) <= WITHIN_M
        return abs(self.reported) <= STILL_M and self.angle <= STILL_DEG


def name_of(structure: dict, parts: list[b.Face] | None = None) -> str:
    """A plane's or a line's name (its JSON object), by the faces of ``parts`` (the
    building's by default)."""
    if "normal" in structure:
        return b.plane_name(np.array(structure["normal"]), np.array(structure["centroid_m"]),
                            parts)
    return b.line_name(np.array(structure["direction"]), np.array(structure["point_m"]), parts)


def answers(block: dict, detector: str, shifts: dict[str, float]) -> list[Answer]:
    """The matched structures of one detector (``"planes"``, ``"plane_lines"``) of a
    ``structures_3d`` block, named by the truth's, with the displacements ``shifts`` (each
    changed face's shift along its normal, metres) injected."""
    found = []
    for pair in block[detector]["matches"]:
        name = name_of(pair["truth"])
        found.append(Answer(name, b.injected(name, shifts), pair["displacement_m"],
                            pair["angle_deg"]))
    return found


def unmatched(block: dict, detector: str, parts: list[b.Face] | None = None
              ) -> tuple[list[str], list[str]]:
    """The names of one detector's missing truth structures and extra map ones (the map's
    named by ``parts``, the faces the map was drawn from), each sorted."""
    return (sorted(name_of(s) for s in block[detector]["missing"]),
            sorted(name_of(s, parts) for s in block[detector]["extra"]))


def largest_still(found: list[Answer]) -> tuple[float, float]:
    """The largest displacement size (metres) and angle (degrees) of the unchanged
    structures."""
    still = [a for a in found if not a.changed]
    return (max((abs(a.reported) for a in still), default=0.0),
            max((a.angle for a in still), default=0.0))
