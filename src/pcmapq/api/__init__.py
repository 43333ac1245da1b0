"""pcmapq as a library: the four things the commands do, each one call, in metres.

    import pcmapq
    result = pcmapq.evaluate("map.pgm", "truth.png", pcmapq.Settings())
    result.to_json()

:func:`evaluate` is ``pcmapq eval``, :func:`inspect` ``pcmapq inspect``,
:func:`track_quality` ``pcmapq track`` (without its files; ``pcmapq.track`` is the package that
does the work), :func:`load_map` the loader every command uses, :func:`read_settings` what
``--config FILE`` reads.
Frames: ``p_truth = s * R(yaw) * p_map + t``.
"""

from __future__ import annotations

from pcmapq.api.calls import inspect, track_quality
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.io import load_map
from pcmapq.results.result import Result
from pcmapq.settings import NoRefConfig, Settings
from pcmapq.settings.file import read_settings
from pcmapq.track import Tracked

__all__ = ["NoRefConfig", "Result", "Settings", "Tracked", "evaluate", "inspect", "load_map",
           "read_settings", "track_quality"]
