"""Do the map's parts agree on where it is? A map that drifted, bent or broke apart has no one
pose that fits it whole, so its global search stands out little; yet each of its parts, placed
on its own by the same global search and ICP, lands near where the map's pose puts it. A map
of another place has parts that land anywhere: each fits some walls somewhere.

The map is cut into eight parts of equal point count: four along its points' first principal
axis, each cut in two across (the quarters of a long corridor map are its stretches). A map of
more points than the alignment keeps (``AlignParams.max_points``) is cut from the points the
alignment keeps of it (:func:`pcmapq.core.voxels.thinned`: voxel centroids, the voxel grown
until about that many remain), so its parts are of equal wall length rather than equal raw
point count, and placing them costs what it costs for a map of that size. Each part
is aligned to the truth with no initial guess (:func:`pcmapq.align.align`); it agrees with the
map's pose when its centroid lands within :data:`AGREE_M` (or :data:`AGREE_RADIUS` of the
map's radius, the larger) of where the map's pose puts it, turned by at most
:data:`AGREE_DEG`. Frames: the map's pose and every part's transform take map-frame points to
the truth frame, ``p_truth = s * R(yaw) * p_map + t``; a map of unknown unit is taken at the
scale its pose found."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pcmapq.align.params import AlignParams
from pcmapq.align.planar import RigidTarget, align
from pcmapq.core.bounds import radius
from pcmapq.core.transform import Similarity2D, wrapped
from pcmapq.core.voxels import thinned

#: Agreement: a part's centroid within this many metres of where the map's pose puts it ...
AGREE_M = 3.0
#: ... or within this share of the map's radius (about its centroid), the larger ...
AGREE_RADIUS = 0.15
#: ... and a part turned by at most this many degrees from the map's pose.
AGREE_DEG = 15.0
#: Parts: bins along the map's first principal axis, and across it.
PIECES = (4, 2)
#: Parts with fewer points than this are not aligned (nothing to place them by).
MIN_POINTS = 50
#: A part that does not agree is taken as broken off, its own pose a start for the regions it
#: holds (:func:`pcmapq.align.regions.regions`), when that pose moves it by at most this share
#: of the map's radius and turns it by at most BROKEN_DEG; farther, it landed on other walls.
BROKEN_RADIUS, BROKEN_DEG = 0.5, 45.0


@dataclass(frozen=True)
class Part:
    """One part of the map placed on its own.

    share: its share of the map's points. centre_m: its centroid where the map's pose puts it,
    truth frame, metres. offset_m: how far its own pose puts that centroid from there, metres;
    turn_deg: how far its own pose turns it from the map's pose, degrees, in [0, 180].
    fitness: its own alignment's fitness. agrees: within the agreement bounds. pose: its own
    map -> truth transform (at the map's scale)."""

    share: float
    centre_m: tuple[float, float]
    offset_m: float
    turn_deg: float
    fitness: float
    agrees: bool
    pose: Similarity2D = Similarity2D()


def pieces(xy: np.ndarray, along: int = 2, across: int = 2) -> np.ndarray:
    """(N,) piece index of each point (N, 2): ``along`` bins of equal count along the points'
    first principal axis, each cut into ``across`` bins of equal count along the second;
    index = bin along * ``across`` + bin across."""
    centred = xy - xy.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    coords = centred @ vectors[:, ::-1]
    first = np.argsort(np.argsort(coords[:, 0], kind="stable"), kind="stable")
    index = first * along // len(xy) * across
    for k in range(along):
        inside = np.flatnonzero(index == k * across)
        rank = np.argsort(np.argsort(coords[inside, 1], kind="stable"), kind="stable")
        index[inside] += rank * across // len(inside)
    return index


def place_parts(map_xy: np.ndarray, truth_xy: np.ndarray, pose: Similarity2D,
                params: AlignParams = AlignParams(),
                target: RigidTarget | None = None) -> list[Part]:
    """The parts of the map (N, 2, map frame; :data:`PIECES`) each aligned to the truth (M, 2,
    metres, truth frame; ``target``: those points prepared for the rigid alignment) with no
    initial guess, against the map's ``pose``."""
    scaled = np.asarray(map_xy, dtype=np.float64).reshape(-1, 2) * pose.scale
    if len(scaled) > params.max_points:
        scaled, _ = thinned(scaled, params.voxel, params.max_points)
    rigid = Similarity2D(pose.tx, pose.ty, pose.yaw)
    if target is None or not target.fits(params):
        target = RigidTarget(truth_xy, params)
    reach = max(AGREE_M, AGREE_RADIUS * radius(scaled))
    labels = pieces(scaled, *PIECES)
    parts = []
    for k in range(PIECES[0] * PIECES[1]):
        part = scaled[labels == k]
        if len(part) < MIN_POINTS:
            continue
        own = align(part, truth_xy, params, target=target)
        centre = part.mean(axis=0, keepdims=True)
        placed = rigid.apply(centre)[0]
        offset = float(np.hypot(*(own.transform.apply(centre)[0] - placed)))
        turn = abs(float(np.degrees(wrapped(own.transform.yaw - rigid.yaw))))
        parts.append(Part(len(part) / len(scaled), (float(placed[0]), float(placed[1])),
                          offset, turn, own.fitness, offset <= reach and turn <= AGREE_DEG,
                          replace(own.transform, scale=pose.scale)))
    return parts


def broken_off(parts: list[Part] | tuple[Part, ...], map_xy: np.ndarray,
               pose: Similarity2D) -> tuple[tuple[Similarity2D, tuple[float, float]], ...]:
    """The poses of the parts that broke off, each with its centroid as the map's ``pose``
    puts it (truth frame, metres): parts that do not agree, moved by at most BROKEN_RADIUS of
    the map's radius (map_xy (N, 2) in map units, scaled by ``pose``) and turned by at most
    BROKEN_DEG."""
    reach = BROKEN_RADIUS * pose.scale * radius(np.asarray(map_xy, dtype=np.float64))
    return tuple((p.pose, p.centre_m) for p in parts
                 if not p.agrees and p.offset_m <= reach and p.turn_deg <= BROKEN_DEG)
