"""Modules pcmapq never uses that a library it loads would import when installed: Open3D loads
Dash, whose notebook support loads IPython, about 0.6 s of a process's start (Dash carries on
without it). :func:`leave_out_unused` marks them absent in pcmapq's own processes: the command's,
its batch workers'. The library, imported in a user's own process, leaves them alone."""

from __future__ import annotations

import sys

__all__ = ["UNUSED", "leave_out_unused"]

#: Modules marked absent in pcmapq's own processes.
UNUSED = ("IPython",)


def leave_out_unused() -> None:
    """Mark :data:`UNUSED` absent in this process (importing one raises ImportError), unless
    already imported."""
    for name in UNUSED:
        sys.modules.setdefault(name, None)  # type: ignore[arg-type]
