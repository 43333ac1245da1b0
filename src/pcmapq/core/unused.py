"""Modules pcmapq never uses that a library it loads would import: Open3D's package imports its
Plotly drawing (``open3d.visualization.draw_plotly``), which loads Plotly and Dash (about 0.2 s
of a process's start), and Dash's notebook support loads IPython when it is installed (about
0.6 s more). :func:`leave_out_unused` keeps them out of pcmapq's own processes: the command's,
its batch workers'. The library, imported in a user's own process, leaves them alone."""

from __future__ import annotations

import sys
from types import ModuleType

__all__ = ["STAND_INS", "UNUSED", "leave_out_unused"]

#: Modules marked absent in pcmapq's own processes (importing one raises ImportError).
UNUSED = ("IPython",)
#: Modules of a package pcmapq loads that the package itself imports by name, replaced in
#: pcmapq's own processes by a stand-in whose every name is a function that raises ImportError.
STAND_INS = ("open3d.visualization.draw_plotly",)


def leave_out_unused() -> None:
    """Mark :data:`UNUSED` absent and put :data:`STAND_INS` in place in this process, unless
    already imported."""
    for name in UNUSED:
        sys.modules.setdefault(name, None)  # type: ignore[arg-type]
    for name in STAND_INS:
        sys.modules.setdefault(name, _stand_in(name))


def _stand_in(name: str) -> ModuleType:
    """A module ``name`` whose every attribute is a function raising ImportError, so that
    ``from name import anything`` works and calling it says what was left out."""
    module = ModuleType(name, "left out of pcmapq's processes (pcmapq.core.unused)")

    def left_out(attribute: str):
        if attribute.startswith("__"):
            raise AttributeError(attribute)

        def call(*args, **kwargs):
            raise ImportError(f"{name}.{attribute} is left out of pcmapq's processes")

        return call

    module.__getattr__ = left_out  # type: ignore[method-assign]
    return module
