"""The frame chain of a run: how each input's points reach the truth's plan, metres.

A 3D cloud becomes a plan by *levelling* (a rotation about a horizontal axis that makes its
floor horizontal, then heights measured from the floor; :mod:`pcmapq.raster.slice`); a 2D map is
a plan already. When both inputs are 3D clouds they are first registered in 3D, and the map is
levelled after that move. The 2D alignment then takes the map's plan to the truth's plan::

    map cloud  --registration_3d (4x4)-->  --map_levelling (3x3, drop z)-->  map plan
    map plan   --planar: p_truth = s * R(yaw) * p_map + t-->  truth plan
    truth cloud  --truth_levelling (3x3, drop z)-->  truth plan
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.core.transform import Similarity2D

#: The documented convention, stored beside the transforms in the JSON.
CONVENTION = "p_truth = s * R(yaw) * p_map + t"


@dataclass(frozen=True)
class Levelling:
    """How a 3D cloud was levelled into a plan: ``p_plan = (rotation @ p)[:2]``, wall band heights
    measured from ``floor_z_m`` (the levelled cloud's floor height, metres)."""

    rotation: np.ndarray
    floor_z_m: float

    @property
    def tilt_deg(self) -> float:
        """The cloud's tilt that was removed, degrees: the angle between +z and the floor's
        normal, which is the rotation's last row (``rotation @ normal = +z``)."""
        r = np.asarray(self.rotation)
        return float(np.degrees(np.arctan2(np.hypot(r[2, 0], r[2, 1]), r[2, 2])))

    def to_dict(self) -> dict:
        return {"matrix": np.asarray(self.rotation).tolist(), "tilt_deg": self.tilt_deg,
                "floor_z_m": self.floor_z_m}

    @classmethod
    def from_dict(cls, doc: dict | None) -> Levelling | None:
        if doc is None:
            return None
        return cls(np.asarray(doc["matrix"], dtype=np.float64), float(doc["floor_z_m"]))


@dataclass(frozen=True)
class Frames:
    """The whole chain (see the module docstring). map_levelling, truth_levelling: None for a 2D
    input; registration_3d: the 4x4 map cloud -> truth cloud transform when both are 3D clouds,
    else None; planar: the 2D alignment of the plans."""

    planar: Similarity2D
    map_levelling: Levelling | None = None
    truth_levelling: Levelling | None = None
    registration_3d: np.ndarray | None = None

    def map_to_truth(self) -> Similarity2D:
        """The map -> truth transform in the plane: ``planar`` after the planar part (x, y, yaw)
        of ``registration_3d``, when there is one."""
        if self.registration_3d is None:
            return self.planar
        return self.planar.compose(Similarity2D.from_matrix(self.registration_3d))

    def to_dict(self) -> dict:
        return {"convention": CONVENTION,
                "map_levelling": None if self.map_levelling is None
                else self.map_levelling.to_dict(),
                "registration_3d": None if self.registration_3d is None
                else np.asarray(self.registration_3d).tolist(),
                "planar": self.planar.to_dict(),
                "truth_levelling": None if self.truth_levelling is None
                else self.truth_levelling.to_dict()}

    @classmethod
    def from_dict(cls, doc: dict) -> Frames:
        reg = doc["registration_3d"]
        return cls(Similarity2D.from_dict(doc["planar"]),
                   Levelling.from_dict(doc["map_levelling"]),
                   Levelling.from_dict(doc["truth_levelling"]),
                   None if reg is None else np.asarray(reg, dtype=np.float64))
