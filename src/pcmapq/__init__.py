"""pcmapq: how good a robot-made map is, measured against a ground-truth map, in metres.

Frame convention, everywhere: ``p_truth = s * R(yaw) * p_map + t``.

The library (:mod:`pcmapq.api`, loaded on first use so that ``pcmapq --version`` stays light)::

    import pcmapq
    result = pcmapq.evaluate("map.pgm", "truth.png", pcmapq.Settings())
"""

from __future__ import annotations

from typing import Any

__version__ = "0.1.0"
__all__ = ["NoRefConfig", "Result", "Settings", "Tracked", "__version__", "evaluate", "inspect",
           "load_map", "read_settings", "track_quality"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from pcmapq import api

        return getattr(api, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
