"""When a run's map went wrong: the worst lasting drop of a figure over its steps."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcmapq.results.figures import MEAN_PRECISION
from pcmapq.track.timeline import Step

#: A fall smaller than this is no drop (the band a good run's curves stay within): a value
#: within it of the peak is still level with the peak.
MIN_DROP = 0.05


@dataclass(frozen=True)
class Drop:
    """The worst lasting fall of a figure along the steps: it peaked at step ``peak``, started
    to fall at step ``start`` (the step after the last one still within :data:`MIN_DROP` of
    the peak: where the map went wrong; a partial map's dip before it, made up later, is
    none) and was lowest at step ``low``, ``size`` below the peak; every later step stays at
    least ``lasting`` below the peak."""

    figure: str
    peak: int
    start: int
    low: int
    size: float
    lasting: float


def worst_drop(steps: list[Step], figure: str = MEAN_PRECISION) -> Drop | None:
    """The largest fall of ``figure`` from its highest value so far that no later step makes
    up (the maximum drawdown of the later steps' best), over the scored steps; None with fewer
    than two, or when it is less than :data:`MIN_DROP`. A map keeps every scan it took, so a
    part that went wrong stays in it and the figure stays down; a dip it recovers from (a
    wall scored before the rest of it was seen) is no fault."""
    scored = [s for s in steps if s.scored and s.figures.get(figure) is not None]
    if len(scored) < 2:
        return None
    values = np.array([s.figures[figure] for s in scored])
    peaks = np.maximum.accumulate(values)
    later_best = np.maximum.accumulate(values[::-1])[::-1]
    worst = int(np.argmax(peaks - later_best))
    lasting = float(peaks[worst] - later_best[worst])
    if lasting < MIN_DROP:
        return None
    peak = int(np.flatnonzero(values[:worst + 1] == peaks[worst])[-1])
    low = peak + int(np.argmin(values[peak:worst + 1]))
    level = np.flatnonzero(values[peak:low + 1] > peaks[worst] - MIN_DROP)
    start = peak + int(level[-1]) + 1
    return Drop(figure, scored[peak].step, scored[start].step, scored[low].step,
                float(peaks[worst] - values[low]), lasting)
