"""The paper's method on the 3D structures of two 3D clouds: their planes and the lines where
planes meet (:mod:`pcmapq.features.planes3d`, :mod:`pcmapq.features.lines3d`), found on each
cloud in the truth frame, matched one to one (the optimal assignment of
:func:`pcmapq.match.one_to_one.assign`) and scored as the 2D detectors are: quality = matched
truth structures / truth structures, precision = matched map structures / map structures, f1.

A truth plane and a map plane may match when their normals are within ``max_angle`` degrees,
their rectangles overlap (the map's, in the truth plane's axes, meets the truth's) and, at the
middle of that overlap, the map plane lies within ``max_offset`` metres of the truth plane
along its normal: that signed distance is the pair's displacement. Two lines may match when
their directions are within ``max_angle``, their segments overlap along the truth line and,
at the middle of that overlap, the map line passes within ``max_offset`` of the truth line:
that distance (>= 0) is the pair's displacement. A pair's cost, in [0, 1], is the mean of its
angle over ``max_angle``, its distance over ``max_offset`` and the share of the smaller
extent it does not overlap.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from pcmapq.features.lines3d import Lines, plane_lines
from pcmapq.features.names import STRUCTURE_NAMES
from pcmapq.features.planes3d import PlaneParams, Planes, find_planes
from pcmapq.match.one_to_one import assign, harmonic_mean
from pcmapq.match.plane_fit import PlaneFit, moved, plane_fit

#: The detectors of 3D structures, in the order they are written and shown.
STRUCTURES = STRUCTURE_NAMES
#: What one structure of each is called in a sentence.
NOUNS = {"planes": "plane", "plane_lines": "line where two planes meet"}

#: Candidate pairs: truth and map indices, costs, displacements (metres), angles (degrees).
Pairs = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class StructureMatching:
    """One detector's matched structures and scores. truth_idx, map_idx: (M,) the pairs,
    sorted by truth index; displacement: (M,) metres (a plane's signed, along the truth
    plane's normal; a line's distance, >= 0); angle: (M,) degrees between them. quality,
    precision, f1: as the 2D detectors' (None when undefined); unscored: why all three are
    None (the truth has nothing to find). missing, extra: the truth's and the map's unmatched
    structures."""

    truth_idx: np.ndarray
    map_idx: np.ndarray
    displacement: np.ndarray
    angle: np.ndarray
    quality: float | None
    precision: float | None
    f1: float | None
    truth_structures: int
    map_structures: int
    missing: np.ndarray
    extra: np.ndarray
    unscored: str | None = None

    @property
    def matched(self) -> int:
        """Matched pairs: truth and map structures matched alike."""
        return len(self.truth_idx)

    def note(self, noun: str) -> str | None:
        """Why a score is undefined, one line (None when all three are defined); ``noun``:
        what one structure is called."""
        if self.unscored is not None:
            return self.unscored
        return None if self.precision is not None else f"no map {noun}"


@dataclass(frozen=True)
class StructureResult:
    """One detector's structures on both sides (truth frame, metres) and their matching."""

    truth: Planes | Lines
    map: Planes | Lines
    matching: StructureMatching


@dataclass(frozen=True)
class Structures3D:
    """The 3D structures of two clouds: each detector's result (:data:`STRUCTURES` order),
    the thresholds they were matched with: ``max_angle`` degrees, ``max_offset`` metres, and
    the planes' own fit that moved the map's structures (None: read from a result without
    it)."""

    detectors: dict[str, StructureResult]
    max_angle: float
    max_offset: float
    fit: PlaneFit | None = None


def plane_pairs(truth: Planes, map_: Planes, max_angle: float, max_offset: float) -> Pairs:
    """Candidate plane pairs (see the module's docstring)."""
    nt, nm = truth.normal[:, None, :], map_.normal[None, :, :]
    dot = np.sum(nt * nm, axis=2)  # (T, M)
    sign = np.where(dot < 0, -1.0, 1.0)
    angle = np.degrees(np.arccos(np.clip(np.abs(dot), 0.0, 1.0)))
    axes, half = truth.axes, truth.extent / 2  # (T, 2, 3), (T, 2)
    uv = np.einsum("tak,tmck->tmca", axes,
                   map_.corners[None, :, :, :] - truth.centre[:, None, None, :])
    lo = np.maximum(uv.min(axis=2), -half[:, None, :])
    hi = np.minimum(uv.max(axis=2), half[:, None, :])
    side = np.clip(hi - lo, 0.0, None)
    inter = side[..., 0] * side[..., 1]
    box = np.prod(uv.max(axis=2) - uv.min(axis=2), axis=2)
    share = inter / np.maximum(np.minimum(np.prod(truth.extent, axis=1)[:, None], box), 1e-12)
    # the middle of the overlap on the truth plane, and the map plane's distance from it
    middle = truth.centre[:, None, :] + np.einsum("tma,tak->tmk", (lo + hi) / 2, axes)
    along = np.abs(dot)
    disp = (sign * map_.offset[None, :] - np.sum(sign[..., None] * nm * middle, axis=2)) / \
        np.maximum(along, 1e-12)
    ok = (angle <= max_angle) & (inter > 0) & (np.abs(disp) <= max_offset)
    i, j = np.nonzero(ok)
    return i, j, _cost(angle[i, j], max_angle, np.abs(disp[i, j]), max_offset,
                       share[i, j]), disp[i, j], angle[i, j]


def line_pairs(truth: Lines, map_: Lines, max_angle: float, max_offset: float) -> Pairs:
    """Candidate line pairs (see the module's docstring)."""
    dt, dm = truth.direction[:, None, :], map_.direction[None, :, :]
    angle = np.degrees(np.arccos(np.clip(np.abs(np.sum(dt * dm, axis=2)), 0.0, 1.0)))
    ends = np.einsum("tk,tmek->tme", truth.direction,
                     map_.ends[None, :, :, :] - truth.point[:, None, None, :])
    half = (truth.length / 2)[:, None]
    lo, hi = np.maximum(ends.min(axis=2), -half), np.minimum(ends.max(axis=2), half)
    overlap = np.clip(hi - lo, 0.0, None)
    share = overlap / np.maximum(np.minimum(truth.length[:, None], map_.length[None, :]), 1e-12)
    at = truth.point[:, None, :] + ((lo + hi) / 2)[..., None] * dt  # (T, M, 3)
    w = at - map_.point[None, :, :]
    perp = w - np.sum(w * dm, axis=2)[..., None] * dm
    dist = np.linalg.norm(perp, axis=2)
    ok = (angle <= max_angle) & (overlap > 0) & (dist <= max_offset)
    i, j = np.nonzero(ok)
    return i, j, _cost(angle[i, j], max_angle, dist[i, j], max_offset, share[i, j]), \
        dist[i, j], angle[i, j]


def _ratio(num: int, den: int) -> float | None:
    """num / den; None (undefined, not 0) when there is nothing to count."""
    return num / den if den > 0 else None


def _cost(angle: np.ndarray, max_angle: float, dist: np.ndarray, max_offset: float,
          share: np.ndarray) -> np.ndarray:
    """The pairs' normalised costs in [0, 1]: the mean of angle / max_angle, distance /
    max_offset and the share of the smaller extent not overlapped."""
    return np.clip((angle / max(max_angle, 1e-12) + dist / max(max_offset, 1e-12)
                    + (1.0 - np.clip(share, 0.0, 1.0))) / 3.0, 0.0, 1.0)


def match_structures(name: str, truth: Planes | Lines, map_: Planes | Lines,
                     max_angle: float, max_offset: float) -> StructureMatching:
    """Match the map's structures of detector ``name`` ("planes" or "plane_lines") to the
    truth's, one to one (both in the truth frame, metres; ``max_angle`` degrees,
    ``max_offset`` metres)."""
    pairs = plane_pairs if name == "planes" else line_pairs
    i, j, cost, disp, angle = pairs(truth, map_, max_angle, max_offset)  # type: ignore[arg-type]
    chosen = assign(i, j, cost, np.ones(len(i), dtype=np.int64))
    order = np.argsort(i[chosen], kind="stable")
    ti, mj = i[chosen][order], j[chosen][order]
    quality, precision = _ratio(len(ti), len(truth)), _ratio(len(mj), len(map_))
    unscored = None
    if not len(truth):  # nothing to find: undefined, not 0
        unscored = f"the truth has no {NOUNS[name]}: nothing to find"
        quality = precision = None
    return StructureMatching(ti, mj, disp[chosen][order], angle[chosen][order], quality,
                             precision, harmonic_mean(quality, precision), len(truth),
                             len(map_), np.setdiff1d(np.arange(len(truth)), ti),
                             np.setdiff1d(np.arange(len(map_)), mj), unscored)


def compare_structures(truth_points: np.ndarray, map_points: np.ndarray, params: PlaneParams,
                       line_margin: float, line_length: float, max_angle: float,
                       max_offset: float, reach: float | None = None,
                       truth_planes: Planes | None = None) -> Structures3D:
    """The planes and plane lines of two clouds (N, 3), both in the truth frame, metres,
    found with ``params`` (lines: extents touching within ``line_margin`` metres, at least
    ``line_length`` metres long) and matched
    with ``max_angle`` degrees and ``max_offset`` metres, the map's planes moved first by the
    planes' own fit (:mod:`pcmapq.match.plane_fit`) to the planes matched so, when it moves
    none more than ``reach`` metres (None: whatever it moves). ``truth_planes``: the truth's
    planes when already found with ``params`` (None: found here). The two clouds' planes are
    found on two threads at once (NumPy and SciPy's work leaves Python's lock)."""
    if truth_planes is not None:
        truth, found = truth_planes, find_planes(map_points, params)
    else:
        with ThreadPoolExecutor(2, thread_name_prefix="pcmapq-planes") as pool:
            truth, found = pool.map(find_planes, (truth_points, map_points), (params, params))
    first = match_structures("planes", truth, found, max_angle, max_offset)
    fit = plane_fit(truth, found, first.truth_idx, first.map_idx, reach)
    planes = [truth, moved(found, fit.matrix)]
    lines = [plane_lines(p, line_margin, line_length) for p in planes]
    both = {"planes": planes, "plane_lines": lines}
    return Structures3D({name: StructureResult(t, m, match_structures(name, t, m, max_angle,
                                                                      max_offset))
                         for name, (t, m) in both.items()}, max_angle, max_offset, fit)

