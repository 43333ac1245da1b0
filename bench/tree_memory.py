"""The resident memory of a process and every process it starts, summed: a command whose
children run beside it (pcmapq's 3D ICP and its 3D consistency map's registrations) holds
their memory too, which its own peak RSS (``os.wait4``) leaves out (that is the largest
single process's)."""

from __future__ import annotations

import os
import resource
import subprocess
import threading

import psutil

__all__ = ["TreeMemory", "waited"]

#: Seconds between two samples.
EVERY = 0.05


class TreeMemory:
    """A thread that sums the resident set of process ``pid`` and of its descendants every
    EVERY seconds until :meth:`stop`, which gives the largest sum, bytes."""

    def __init__(self, pid: int) -> None:
        self._process = psutil.Process(pid)
        self._done = threading.Event()
        self._peak = 0
        self._thread = threading.Thread(target=self._run, name="tree-memory", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._done.is_set():
            self._peak = max(self._peak, self._sum())
            self._done.wait(EVERY)

    def _sum(self) -> int:
        try:
            tree = [self._process, *self._process.children(recursive=True)]
        except psutil.Error:  # the process has ended
            return 0
        total = 0
        for process in tree:
            try:
                total += process.memory_info().rss
            except psutil.Error:  # ended between the listing and the reading
                pass
        return total

    def stop(self) -> int:
        """Stop sampling; the largest sum seen, bytes."""
        self._done.set()
        self._thread.join()
        return self._peak


def waited(proc: subprocess.Popen) -> tuple[int, resource.struct_rusage, float]:
    """Wait for ``proc`` (``os.wait4``): its wait status, its resource usage, and its peak
    memory in GB, the larger of its own peak RSS and the largest sum of its and its
    descendants' resident sets sampled meanwhile (:class:`TreeMemory`)."""
    tree = TreeMemory(proc.pid)
    _, status, usage = os.wait4(proc.pid, 0)
    return status, usage, max(usage.ru_maxrss / 1024**2, tree.stop() / 1024**3)
