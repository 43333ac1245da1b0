"""A progress bar over a batch's rows, on the terminal only (as ``pcmapq eval``'s spinner)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from pcmapq.batch.row import Outcome


@contextmanager
def row_bar(console: Console, total: int, enabled: bool) -> Iterator[Callable[[Outcome], None]]:
    """A bar over ``total`` rows, advanced by each Outcome given to the function yielded, with
    the counts so far (computed, skipped, failed); nothing when not a terminal."""
    if not (enabled and console.is_terminal):
        yield lambda outcome: None
        return
    counts: Counter[str] = Counter()
    columns = (TextColumn("rows"), BarColumn(), MofNCompleteColumn(),
               TextColumn("{task.fields[note]}"), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task("rows", total=total, note="")

        def tick(outcome: Outcome) -> None:
            counts[outcome.status] += 1
            note = ", ".join(f"{counts[s]} {s}" for s in ("computed", "skipped", "failed")
                             if counts[s])
            bar.update(task, advance=1, note=note)

        yield tick
