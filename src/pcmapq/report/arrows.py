"""The arrows of the pictures (:mod:`pcmapq.report.plot`, the report's interactive map): where
each starts and where it points, and the one scale every panel of a figure draws them at.

One convention holds for every arrow: it starts at the truth's feature (a region: where the
region fits the truth on its own) and points to where the map has it, so it shows the map's
error. A matched feature's arrow is its displacement (truth feature to map feature); a
region's is the opposite of its offset (:class:`~pcmapq.align.regions.Consistency`, which
moves the region onto the truth). Truth frame, metres.
"""

from __future__ import annotations

import math

import numpy as np

from pcmapq.report.canvas import size_m, window
from pcmapq.report.style import ARROW_SHARE, MAX_ARROW_SCALE
from pcmapq.results.result import DetectorResult, Result

#: The round scales: these times a power of ten.
NICE = (1, 2, 5)


def feature_arrows(det: DetectorResult) -> tuple[np.ndarray, np.ndarray]:
    """(tails, vectors), each (M, 2) metres, of a detector's matched features: from each
    matched truth feature to its map feature."""
    return det.truth_xy, det.matching.displacement


def region_arrows(result: Result) -> tuple[np.ndarray, np.ndarray]:
    """(tails, vectors), each (K, 2) metres, of the regions of the consistency map: from
    where each region fits the truth to where the map has it (its centre), the opposite of
    its offset; none without a consistency map."""
    c = result.consistency
    if c is None:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return c.centre + c.offset, -c.offset


def longest_arrow(result: Result) -> float:
    """The longest displacement any panel of the vectorial map draws (every matched feature
    of every detector, every region), metres; 0 when there is none."""
    vectors = [feature_arrows(d)[1] for d in result.detectors.values()]
    vectors.append(region_arrows(result)[1])
    lengths = np.hypot(*np.vstack(vectors).T) if vectors else np.zeros(0)
    return float(lengths.max()) if len(lengths) else 0.0


def round_scale(bound: float) -> float:
    """The largest 1, 2 or 5 times a power of ten not above ``bound``, within 1 and
    MAX_ARROW_SCALE."""
    if bound >= MAX_ARROW_SCALE:
        return MAX_ARROW_SCALE
    if bound <= 1.0:
        return 1.0
    power = 10.0 ** math.floor(math.log10(bound))
    return max(n * power for n in NICE if n * power <= bound * (1 + 1e-12))


def auto_arrow_scale(result: Result) -> float:
    """The scale of every arrow of ``result``'s pictures: the largest round scale
    (:func:`round_scale`) that draws the longest arrow no longer than ARROW_SHARE of the
    larger side of what a panel shows (:func:`~pcmapq.report.canvas.window`), at least 1
    (then the longest may be longer), at most MAX_ARROW_SCALE (also when there is no arrow)."""
    side = max(size_m(result, window(result)))
    longest = longest_arrow(result)
    return round_scale(ARROW_SHARE * side / longest if longest > 0 else math.inf)


def arrow_scale(result: Result, chosen: float | None = None) -> float:
    """``chosen`` (``--arrow-scale``) when given, else :func:`auto_arrow_scale`."""
    return auto_arrow_scale(result) if chosen is None else float(chosen)


def arrow_label(scale: float) -> str:
    """The arrows' legend entry: their scale, with an example in metres, and direction."""
    return f"displacement x{scale:g} ({0.1:g} m drawn {0.1 * scale:g} m), truth to map"


#: The arrows' convention in words, for a legend's title.
ARROW_WORDS = "arrows from the truth to where the map has it (the map's error)"
