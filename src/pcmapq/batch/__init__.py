"""Many evaluations at once (``pcmapq batch``): the manifest's rows, run on local processes
or a Dask cluster, resumable, each row's failure its own."""

from pcmapq.batch.manifest import Row, glob_rows, parse_assignments, read_rows
from pcmapq.batch.row import Outcome, Task, run_row
from pcmapq.batch.run import run_batch

__all__ = ["Outcome", "Row", "Task", "glob_rows", "parse_assignments", "read_rows",
           "run_batch", "run_row"]
