"""The command line: parse options, call the pipeline, show and save the result. No logic.

One module per command (:mod:`~pcmapq.cli.evaluate`, :mod:`~pcmapq.cli.map_scans`,
:mod:`~pcmapq.cli.inspect`, :mod:`~pcmapq.cli.compare`, :mod:`~pcmapq.cli.batch`,
:mod:`~pcmapq.cli.track`), each registering itself on :data:`~pcmapq.cli.app.app`.
"""

from __future__ import annotations

from pcmapq.cli import batch, compare, evaluate, inspect, map_scans, track  # noqa: F401
from pcmapq.cli.app import app

__all__ = ["app"]
