"""The no-reference figures of a 3D map as one JSON-ready record (``pcmapq inspect``, the
``"noref"`` block of ``eval``): MME, MPV, MOM and what they were computed over."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from pcmapq.core.errors import EvaluationError
from pcmapq.core.voxels import voxel_centroids
from pcmapq.metrics.noref import LIDAR_RADIUS, MAX_NN, MIN_KNN, mom, scores
from pcmapq.metrics.orthogonal import MAX_WARD_POINTS, extract_orthogonal_subset

#: A sampled pass extracts MOM's planes from the map reduced at this share of the radius: every
#: planar region still holds tens of points, for a small share of the map's own pass.
SAMPLED_MOM_VOXEL = 1 / 3


def _finite(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None


def _mean_note(over: int, neighboured: int, radius: float, min_knn: int) -> str | None:
    """Why a mean over ``over`` points is no figure (None when it is one): no point has more
    than ``min_knn`` neighbours within ``radius`` metres, or (MME) none of those that have
    has a neighbourhood of positive volume (its points on a plane or a line)."""
    if over:
        return None
    if neighboured:
        return (f"no point's neighbourhood within {radius:g} m has volume (all flat or "
                "straight: their entropy is not defined)")
    return (f"no point has more than {min_knn} neighbours within {radius:g} m (a larger "
            "radius, or a denser cloud)")


def noref_figures(points: np.ndarray, radius: float = LIDAR_RADIUS, min_knn: int = MIN_KNN,
                  max_nn: int = MAX_NN, orth_subset: Sequence[np.ndarray] | None = None,
                  mom_source: np.ndarray | None = None,
                  max_ward: int = MAX_WARD_POINTS, sample: int = 0) -> dict[str, Any]:
    """MME (nats), MPV and MOM (m^2) of ``points`` (N, 3 metres) with their parameters.

    MOM uses ``orth_subset`` (planes in the map's frame) or else extracts one from
    ``mom_source`` (map-metrics: the first scan; None: the map itself); when none can be found,
    ``mom`` is None and ``mom_note`` says why (``max_ward``: see
    :func:`~pcmapq.metrics.orthogonal.extract_orthogonal_subset`). ``sample``: MME and MPV
    over that many points drawn at random, with their standard errors, and MOM's planes
    extracted from the map reduced to one point per cell of ``SAMPLED_MOM_VOXEL`` times the
    radius (when neither planes nor a source are given; 0: every point, as map-metrics). Figures
    that are not finite are None; ``mme_note`` and ``mpv_note`` say why MME or MPV is (no point
    with enough neighbours).
    """
    coarse = 0 < sample < len(points) and orth_subset is None and mom_source is None
    if coarse:
        mom_source = voxel_centroids(points, radius * SAMPLED_MOM_VOXEL)
    reuse = orth_subset is None and mom_source is None  # the planar points of this pass
    s = scores(points, radius, min_knn, with_flat=reuse, sample=sample)
    note = None
    planes = orth_subset
    source = "given" if planes is not None else "extracted"
    if planes is None:
        try:
            planes = extract_orthogonal_subset(points if mom_source is None else mom_source,
                                               radius, max_nn, planar=s.flat,
                                               max_ward=max_ward)
        except EvaluationError as exc:
            note, source = str(exc), None
    value = None if planes is None else _finite(mom(points, planes, radius))
    return {
        "mme": _finite(s.mme),
        "mme_note": _mean_note(s.mme_points, s.mpv_points, radius, min_knn),
        "mpv": _finite(s.mpv),
        "mpv_note": _mean_note(s.mpv_points, s.mpv_points, radius, min_knn),
        "mom": value, "mom_note": note,
        "points": s.total_points, "mme_points": s.mme_points, "mpv_points": s.mpv_points,
        "sampled_points": s.sampled_points, "mme_se": _finite(s.mme_se),
        "mpv_se": _finite(s.mpv_se),
        "radius_m": radius, "min_knn": min_knn, "max_nn": max_nn, "orth_subset": source,
        "orth_plane_points": None if planes is None else [len(p) for p in planes],
        "orth_voxel_m": radius * SAMPLED_MOM_VOXEL if coarse else None,
    }
