"""2D alignment of a map to the truth, and 3D registration of two clouds.

Frames: an :class:`Alignment`'s ``transform`` takes map-frame points to the truth frame,
``p_truth = s * R(yaw) * p_map + t``, lengths in truth units (metres): s = 1, or with
``scale=True`` the estimated scale of a map of unknown unit (a scanned plan, a map exported as a
picture), truth units per map unit.

Modules: :mod:`~pcmapq.align.params` (:class:`AlignParams`, the tunables),
:mod:`~pcmapq.align.planar` (:func:`align`: global search, then ICP),
:mod:`~pcmapq.align.coarse` (the global search), :mod:`~pcmapq.align.point_to_point`,
:mod:`~pcmapq.align.point_to_line` and :mod:`~pcmapq.align.similarity_icp` (the ICP stages),
:mod:`~pcmapq.align.rigid3d` (3D clouds; it loads Open3D on import, so it is not imported
here) with :mod:`~pcmapq.align.plan_guess` (its second guess, from the two clouds' plans).
Importing this package loads no Open3D: it is imported where ICP runs. The planar alignment
(SciPy, Numba) loads on first use of its names, so that the settings, which hold
:class:`AlignParams`, load none of it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from pcmapq.align.params import AlignParams
from pcmapq.core.transform import Similarity2D

if TYPE_CHECKING:
    from pcmapq.align.planar import Alignment, align, align_similarity, score

__all__ = ["AlignParams", "Alignment", "Similarity2D", "align", "align_similarity", "score"]

#: The names of :mod:`pcmapq.align.planar`, loaded on first use.
_PLANAR = ("Alignment", "align", "align_similarity", "score")


def __getattr__(name: str) -> Any:
    if name in _PLANAR:
        value = getattr(importlib.import_module("pcmapq.align.planar"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
