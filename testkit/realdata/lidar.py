"""The LiDAR registration pair: two real scans with their true transform."""

from __future__ import annotations

from pathlib import Path

from ..runs import Run, timed_evaluate


def pair(data: Path) -> Run:
    """The source scan scored against the target scan (both 3D: registered in 3D)."""
    folder = data / "registration"
    return timed_evaluate(folder / "source.ply", folder / "target.ply")
