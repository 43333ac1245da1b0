"""A function run in a child process of its own, for compiled code that holds Python's lock
while it runs (small_gicp's registration): the calling process's other threads go on beside
it. The function (defined at a module's top level) and its arguments are pickled to
``python -m pcmapq.core.child``'s standard input, and its result or exception comes back on its
standard output: the same code on the same numbers, so the same result bit for bit.

Starting a child costs 0.2-0.5 s (its imports: NumPy and small_gicp, SciPy too for the 3D
consistency map), so callers use one from CHILD_POINTS points of work.
"""

from __future__ import annotations

import importlib
import os
import pickle
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from pcmapq.core.errors import EvaluationError

__all__ = ["CHILD_POINTS", "in_child"]

#: Points of work (source and target, all stages) from which a child process pays for its start.
CHILD_POINTS = 200_000

T = TypeVar("T")


def in_child(what: str, function: Callable[..., T], *args: Any) -> T:
    """``function(*args)`` run in a child process; its exception raised here as it was raised
    there. ``what``: the work, named in the one line of EvaluationError raised when the child
    itself fails (killed, out of memory)."""
    package_root = str(Path(__file__).resolve().parents[2])  # the pcmapq this one is
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [package_root, *filter(None, [os.environ.get("PYTHONPATH")])]))
    done = subprocess.run(
        [sys.executable, "-m", __name__],
        input=pickle.dumps((function.__module__, function.__qualname__, args), protocol=5),
        capture_output=True, env=env, check=False)
    if done.returncode != 0:
        lines = done.stderr.decode(errors="replace").strip().splitlines()
        raise EvaluationError(f"{what}'s process failed (exit code {done.returncode})"
                              f"{': ' + lines[-1] if lines else ''}")
    ok, value = pickle.loads(done.stdout)
    if not ok:
        raise value
    return value


def _main() -> None:
    """The child: the call from standard input, ``(True, result)`` or ``(False, exception)`` to
    standard output; whatever the function prints goes to standard error."""
    module, name, args = pickle.load(sys.stdin.buffer)
    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    try:
        reply = (True, getattr(importlib.import_module(module), name)(*args))
    except Exception as exc:  # handed to the caller, which raises it
        reply = (False, exc)
    out.write(pickle.dumps(reply, protocol=5))
    out.close()


if __name__ == "__main__":
    _main()
