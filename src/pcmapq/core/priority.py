"""Background threads' priority: work that is not on an evaluation's longest path (the
truth's features and planes, the no-reference figures) runs BACKGROUND_NICE nicer than the
evaluation, so it takes the cores the evaluation leaves idle rather than slowing the steps
everything waits for (the map's 3D registration)."""

from __future__ import annotations

import os
import threading

#: How much nicer a background thread runs (Linux schedules threads as tasks).
BACKGROUND_NICE = 10


def lower_priority() -> None:
    """Make the calling thread BACKGROUND_NICE nicer; elsewhere than Linux, nothing."""
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), BACKGROUND_NICE)
    except (AttributeError, OSError):  # not Linux: the thread keeps the process's priority
        pass
