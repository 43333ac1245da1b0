"""What an evaluation found, as data (:class:`Findings`) and its blocks: one detector's
outcome, the overlap and verdict; and the rounding every saved number goes through."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pcmapq.core.frames import Frames
from pcmapq.core.grid import MetricGrid
from pcmapq.core.stats import Stats
from pcmapq.core.transform import Similarity2D
from pcmapq.features import Features
from pcmapq.match import Matching
from pcmapq.metrics.distances import Distances
from pcmapq.metrics.map_gaussians import MapGaussians

if TYPE_CHECKING:  # the alignment modules load Open3D; a result only holds their outputs
    from pcmapq.align import Alignment
    from pcmapq.align.parts import Part
    from pcmapq.align.regions import Consistency
    from pcmapq.align.regions3d import Consistency3D
    from pcmapq.align.rigid3d import Registration3D
    from pcmapq.match.structures import Structures3D

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


@dataclass(frozen=True)
class Findings:
    """What an evaluation found, as data (:class:`~pcmapq.results.result.Result` adds its
    JSON and CSV views); all coordinates in the truth frame, metres.

    frames: the chain from each input to the truth's plan (levelling, 3D registration, the 2D
    alignment; :mod:`pcmapq.core.frames`). settings: the options it ran with
    (``Settings.to_dict()``, metres and degrees); command: the command line that made it
    (``pcmapq eval ...``, defaults left out), None from the library. noref: each input's
    no-reference figures, ``{"map": ..., "truth": ...}``
    (:func:`pcmapq.evaluation.noref_figures.input_figures`), None when not asked for.
    truth_sha256: the truth file's SHA-256 (hex; None for a result made without its file), so
    that results of one truth are known as such however its path was written. rooms: the
    rooms detector's rooms, each with its status (:func:`pcmapq.match.rooms.room_table`), None
    when it did not run. map_message: the recording's message the map was read from (topic,
    index, ``time_s`` from the recording's start, header ``stamp_s``), None for a file.
    map_3d: MapEval's AWD and SCS of two 3D clouds in one frame
    (:mod:`pcmapq.metrics.map_gaussians`), None otherwise.
    consistency_3d: two 3D clouds' 3D consistency map (:mod:`pcmapq.align.regions3d`), None
    otherwise.
    structures: the 3D structures of two 3D clouds registered in 3D, matched one to one
    (:mod:`pcmapq.match.structures`), None when not found.
    truth_occupied, map_occupied (and the overlap's footprint): the rasters on ``grid``; None
    in a result read back by :meth:`Result.from_json`, which holds everything the JSON holds and no
    more.
    """

    map_path: Path
    map_kind: str
    truth_path: Path
    truth_kind: str
    grid: MetricGrid
    alignment: Alignment
    overlap: Overlap
    distances: Distances
    registration_3d: Registration3D | None
    distances_3d: Distances | None
    threshold: float
    full: bool
    detectors: dict[str, DetectorResult]
    truth_occupied: np.ndarray | None
    map_occupied: np.ndarray | None
    frames: Frames
    footprint_rule: str = "known"
    settings: dict | None = None
    command: str | None = None
    noref: dict | None = None
    consistency: Consistency | None = None
    truth_sha256: str | None = None
    rooms: dict | None = None
    map_message: dict | None = None
    map_3d: MapGaussians | None = None
    consistency_3d: Consistency3D | None = None
    structures: Structures3D | None = None

    @property
    def transform(self) -> Similarity2D:
        """The map -> truth transform in the plane (``p_truth = s * R(yaw) * p_map + t``): the
        2D alignment after the 3D registration's planar part, when there is one."""
        return self.frames.map_to_truth()

    def note(self, name: str) -> str | None:
        """Why detector ``name``'s quality, precision or f1 is undefined (None if defined)."""
        scope = "" if self.full else "inside the footprint"
        return self.detectors[name].matching.note(scope)

    def notes(self) -> list[str]:
        """One line per detector with an undefined score: ``name: n/a: why``."""
        return [f"{name}: n/a: {note}" for name in self.detectors
                if (note := self.note(name)) is not None]
