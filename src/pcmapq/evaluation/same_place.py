"""Does the map show the truth's place? How much of the truth it covers and how well the two
agree there (:func:`overlap`), the confidence that one pose places it there (:func:`confidence`),
the verdict (:func:`verdict`: the same place; the same place, but a map no single pose fits
whole; another place) and the one line that says why not and what to try (:func:`refusal`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from pcmapq.align import Alignment
from pcmapq.align.free_space import CLEAR_M
from pcmapq.align.parts import Part
from pcmapq.core.bounds import radius
from pcmapq.core.morphology import outline
from pcmapq.core.words import count
from pcmapq.evaluation.inputs import MAP_CROP, OUTLINE_M
from pcmapq.io import OccupancyMap, PointMap
from pcmapq.io.extent import far_points
from pcmapq.metrics.distances import DistanceField
from pcmapq.results.result import INCONSISTENT, LOW, OTHER, SAME, Overlap
from pcmapq.settings import Settings

#: Confidence terms (see :func:`confidence`): the distinctiveness worth full confidence, the
#: truth recalls and the agreements worth none and full confidence.
FULL_DISTINCT = 0.2
RECALL_NONE, RECALL_FULL = 0.4, 0.8
AGREE_NONE, AGREE_FULL = 0.7, 0.9
#: The larger of coverage and fitness worth none and full confidence. A map lies on its truth's
#: place one way or the other: a partial map lies on the truth (high fitness), a map larger
#: than its truth covers it (high coverage). A map that hangs off the truth (a wrong --init or
#: --init-3d, --no-align on a map in another frame) has a sliver of each on the other, where
#: its walls may agree however well. Maps of their own place in docs/validation.md reach 0.37
#: and more (a Halmstad map against its furniture-free layout); the sample hung 14-19 m off
#: its plan by --init 0.14-0.21, the 3D building turned 90 degrees by --init-3d 0.09.
SHARE_NONE, SHARE_FULL = 0.2, 0.4
#: A map whose radius exceeds the truth's by this factor cannot be a part of it (a scale).
OVERSIZE = 1.5
#: A map below the minimum confidence still shows the truth's place when at least this many of
#: its eight parts, each placed on its own, agree with its pose (:mod:`pcmapq.align.parts`):
#: two let more maps of other, same-looking office floors through (docs/validation.md).
MIN_AGREEING = 3
#: A map below the minimum confidence also shows the truth's place when its pose stands out this
#: much in the global search (no pose elsewhere scores within 70 % of it) and more than
#: RECALL_NONE of the truth it covers lies near it: a map bent so far that half of it is off
#: the truth, whose parts (an eighth of an office floor each) fit other offices as well as their
#: own. No map of another place in docs/validation.md stands out this much.
STANDS_OUT = 0.3
#: A map with free space is of another place only with evidence that it is: at its pose it
#: saw through SEEN_THROUGH or more of the truth's walls it covers (they lie on its free cells:
#: a laser sees nothing through a wall; :mod:`pcmapq.align.free_space`), or less than
#: ON_TRUTH of its free cells lie on the truth's known cells, or RECALL_NONE or less of the
#: truth it covers lies near its walls. Without such evidence it is scored and flagged as
#: placed with low confidence: a cluttered room fits another room of its house, or of another
#: building, and nothing it holds tells which. The bounds lie between what maps of their own
#: place and maps of other places give (docs/validation.md): a map of its own place sees
#: through few of the truth's walls, with nearly all its free space on it; one of another
#: place sees through many, but for a one-room map that fits a room of another office; a map
#: under heavy clutter sees through few walls anywhere, but much of its free space lies off
#: another layout at its best pose.
SEEN_THROUGH, ON_TRUTH = 0.1, 0.8


def verdict(confidence: float, min_confidence: float, parts: Sequence[Part],
            distinct: float | None = None, recall: float = 0.0,
            seen_through: float | None = None, on_truth: float | None = None) -> str:
    """SAME when the confidence reaches ``min_confidence``; else INCONSISTENT when at least
    MIN_AGREEING of the map's ``parts`` agree with its pose, or when its pose's distinctiveness
    ``distinct`` reaches STANDS_OUT with a truth ``recall`` above RECALL_NONE; else, for a map
    with free space placed by a rigid search that weighed it (``seen_through`` and
    ``on_truth`` not None), LOW when it saw through less than SEEN_THROUGH of the truth's
    walls it covers, ``on_truth`` (the share of its free cells on the truth's known cells)
    reaches ON_TRUTH and ``recall`` is above RECALL_NONE; else OTHER."""
    if confidence >= min_confidence:
        return SAME
    if sum(p.agrees for p in parts) >= MIN_AGREEING:
        return INCONSISTENT
    if distinct is not None and distinct >= STANDS_OUT and recall > RECALL_NONE:
        return INCONSISTENT
    if (seen_through is not None and on_truth is not None and seen_through < SEEN_THROUGH
            and on_truth >= ON_TRUTH and recall > RECALL_NONE):
        return LOW
    return OTHER


def confidence(distinct: float | None, recall: float, agreement: float = 0.0,
               share: float = 1.0) -> float:
    """That the map shows the truth's place, [0, 1]: the smallest of distinct / FULL_DISTINCT,
    (recall - RECALL_NONE) / (RECALL_FULL - RECALL_NONE) and (share - SHARE_NONE) /
    (SHARE_FULL - SHARE_NONE), clipped. ``distinct``: the global search's distinctiveness of the
    final pose (None without a search: ``--init``, ``--no-align``, a 3D registration; then the
    other terms alone); ``recall``: share of the covered truth walls near the map; ``share``:
    the larger of the coverage and the fitness. 0.5 is distinctiveness 0.1, recall 0.6 or
    share 0.3.

    A map that lies on the truth both ways is the truth's place even when the place is
    symmetric (a round room, a square hall: the pose is ambiguous, the scores are not), so
    ``agreement`` (fitness x recall) gives confidence on its own:
    (agreement - AGREE_NONE) / (AGREE_FULL - AGREE_NONE), 0.5 at 0.8; the larger one counts."""
    terms = [(recall - RECALL_NONE) / (RECALL_FULL - RECALL_NONE),
             (share - SHARE_NONE) / (SHARE_FULL - SHARE_NONE)]
    if distinct is not None:
        terms.append(distinct / FULL_DISTINCT)
    agreed = (agreement - AGREE_NONE) / (AGREE_FULL - AGREE_NONE)
    return float(np.clip(max(min(terms), agreed), 0.0, 1.0))


def overlap(truth_occ: np.ndarray, to_map: DistanceField, footprint: np.ndarray,
            alignment: Alignment, resolution: float, free: np.ndarray | None = None) -> Overlap:
    """How much of the truth the map covers, how well the two agree there, and the confidence
    that they show one place; ``to_map`` is each cell's distance to the nearest map wall,
    metres, on a grid of ``resolution`` metres; ``free``: the map's free cells on that grid
    (None for a map without free space). The recall counts the truth's walls by their
    outline (:data:`~pcmapq.evaluation.inputs.OUTLINE_M`): a map sees a filled block's faces,
    not its inside; so does the share of them the map saw through (on its free cells farther
    than :data:`~pcmapq.align.free_space.CLEAR_M` from its walls)."""
    seen = truth_occ & footprint
    coverage = float(seen.sum() / truth_occ.sum()) if truth_occ.any() else 0.0
    tolerance = alignment.tolerance_m
    faces = outline(truth_occ, OUTLINE_M / resolution) & footprint
    near = to_map[faces]
    recall = float((near <= tolerance).mean()) if faces.any() else 0.0
    through = None
    if free is not None:
        through = float((free[faces] & (near > CLEAR_M)).mean()) if faces.any() else 0.0
    agreement = alignment.fitness * recall
    return Overlap(footprint, coverage, recall, agreement,
                   confidence(alignment.distinctiveness, recall, agreement,
                              max(coverage, alignment.fitness)),
                   seen_through=through)


def refusal(source: OccupancyMap | PointMap, truth_path: Path, alignment: Alignment,
            cover: Overlap, settings: Settings, map_xy: np.ndarray, truth_xy: np.ndarray) -> str:
    """One line: why the map seems not to show the truth's place, and the likely cause with the
    option that addresses it."""
    map_path = source.path
    distinct = alignment.distinctiveness
    share = ("" if max(cover.coverage, alignment.fitness) >= SHARE_FULL else
             f"it covers {cover.coverage:.0%} of the truth and {alignment.fitness:.0%} of it "
             "lies on the truth's walls, ")
    why = (share + f"{cover.truth_recall:.0%} of the truth it covers lies near the map" +
           ("" if cover.seen_through is None else
            f", it saw through {cover.seen_through:.0%} of the truth's walls there") +
           ("" if distinct is None else
            f", the best pose scores {distinct:.0%} above the best one elsewhere") +
           ("" if not cover.parts else
            f", {sum(p.agrees for p in cover.parts)} of its "
            f"{count(len(cover.parts), 'part')} placed on their own land near that pose"))
    size = radius(map_xy) / max(radius(truth_xy), 1e-12)
    option = settings.alignment
    far = far_points(source, MAP_CROP)
    if far:
        cause = far
    elif option.init is not None or option.init_3d is not None or not option.enabled:
        cause = ("the given frame: a wrong --init or --init-3d start, or --no-align; drop them "
                 "for a global search")
    elif not option.scale and size > OVERSIZE:
        cause = (f"a scale that differs: the map spans {size:.1f} times the truth; try "
                 "--scale auto")
    elif cover.seen_through is not None and cover.seen_through >= SEEN_THROUGH:
        cause = ("a map of another place: where its walls fit best, the robot saw through the "
                 "truth's walls" + ("" if option.scale else " (or of another scale: --scale auto)"))
    elif (alignment.free_on_truth is not None and cover.seen_through is not None
          and alignment.free_on_truth < ON_TRUTH):
        cause = (f"a map of another place: where its walls fit best, "
                 f"{1 - alignment.free_on_truth:.0%} of its free space lies off the truth"
                 + ("" if option.scale else " (or of another scale: --scale auto)"))
    elif cover.truth_recall >= RECALL_FULL:
        cause = ("a map too cluttered or distorted for its pose to stand out (the truth's walls "
                 "lie near it); --init with a rough pose places it")
    elif not option.scale:
        cause = "a map of another place, or of another scale (--scale auto)"
    else:
        cause = f"a map of another place (best scale found {alignment.transform.scale:.3g})"
    return (f"{map_path}: does not seem to show the place of {truth_path}: confidence "
            f"{cover.confidence:.2f} < {option.min_confidence} ({why}); likely cause: "
            f"{cause}; --force scores it anyway")
