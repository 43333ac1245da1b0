"""The blocks of a :class:`~pcmapq.results.result.Result`: one detector's outcome, the overlap
and verdict, and the rounding every saved number goes through."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pcmapq.core.stats import Stats
from pcmapq.features import Features
from pcmapq.match import Matching

if TYPE_CHECKING:
    from pcmapq.align.parts import Part

#: Decimals kept in saved numbers: micrometres, so reruns give byte-identical files.
DECIMALS = 6
#: The verdicts on whether a map shows the truth's place (see
#: :mod:`pcmapq.evaluation.same_place`): one pose fits it; it is of the truth's place but no
#: single pose fits it whole (scored); it shows another place (refused unless ``--force``).
SAME, INCONSISTENT, OTHER = "same place", "same place, inconsistent map", "another place"
#: A map with free space placed below the minimum confidence where nothing it saw contradicts
#: the truth: scored, and flagged with the search's two best poses (it may show the truth's
#: place or another that looks alike; nothing it holds tells which).
LOW = "placed with low confidence"


@dataclass(frozen=True)
class DetectorResult:
    """One detector's features on both sides (truth frame, metres) and their matching."""

    truth: Features
    map: Features
    matching: Matching

    @property
    def truth_xy(self) -> np.ndarray:
        """Matched truth features, (M, 2) metres."""
        return self.truth.xy[self.matching.truth_idx]

    @property
    def map_xy(self) -> np.ndarray:
        """Where each matched truth feature is in the map: truth_xy + displacement, (M, 2) m."""
        return self.truth_xy + self.matching.displacement

    @property
    def distances(self) -> np.ndarray:
        """Length of each displacement, (M,) metres."""
        return np.linalg.norm(self.matching.displacement, axis=1)

    def displacement_stats(self) -> Stats:
        """Statistics of the displacement lengths, metres (undefined with no match)."""
        return Stats.of(self.distances)


@dataclass(frozen=True)
class Overlap:
    """What part of the truth the map covers and how well they agree there.

    footprint: (rows, cols) bool on the truth's grid, the area the map observed (None in a
        result read back from JSON).
    coverage: share of the truth's occupied cells inside the footprint, [0, 1].
    truth_recall: share of those within the fit tolerance of a map occupied cell, [0, 1].
    agreement: alignment fitness times truth_recall.
    confidence: that one pose places the map on the truth's place, [0, 1] (see
        same_place.confidence).
    verdict: SAME (confidence at least the minimum), INCONSISTENT (below it, but its parts
        placed on their own agree with its pose), LOW (below it, a map with free space that saw
        through few of the truth's walls) or OTHER.
    parts: the map's parts placed on their own (:mod:`pcmapq.align.parts`); empty when the
        confidence alone settled the verdict.
    seen_through: for a map with free space, the share of the truth's wall faces inside the
        footprint that lie on the map's free cells farther than
        :data:`~pcmapq.align.free_space.CLEAR_M` from its walls: walls the map saw through,
        [0, 1]; None for a map without free space.
    """

    footprint: np.ndarray | None
    coverage: float
    truth_recall: float
    agreement: float
    confidence: float = 0.0
    verdict: str = SAME
    parts: tuple[Part, ...] = ()
    seen_through: float | None = None


def rounded(value):
    """Round every float in a nested structure to DECIMALS (and turn -0.0 into 0.0); tuples
    become lists, as JSON writes them."""
    if isinstance(value, float):
        return round(value, DECIMALS) + 0.0
    if isinstance(value, dict):
        return {k: rounded(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [rounded(v) for v in value]
    return value
