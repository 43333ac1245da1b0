"""The command line's terminal side: usage errors, pcmapq's errors and warnings each in one
line on stderr, and progress shown only on a terminal."""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import typer
from rich.console import Console
from rich.progress import Progress
from typer.core import TyperGroup

try:  # recent typer carries its own copy of click
    from typer._click.exceptions import NoSuchOption, UsageError
except ImportError:  # older typer runs on click itself
    from click.exceptions import NoSuchOption, UsageError

from pcmapq.core.errors import EvaluationError, InputError

HELP_WIDTH = 200


class OneLineUsageErrors(TyperGroup):
    """pcmapq's commands, with a usage error (unknown option or command, bad or missing value)
    said in one line like pcmapq's own errors, exit 2, instead of click's four lines."""

    def main(self, args: Sequence[str] | None = None, prog_name: str | None = None,
             complete_var: str | None = None, standalone_mode: bool = True,
             **extra: Any) -> Any:
        """Click's main, every command's warnings shown as pcmapq's (:func:`show_warnings`);
        in standalone mode, a usage error becomes one line on stderr."""
        with show_warnings(Console(stderr=True)):
            return self._main(args, prog_name, complete_var, standalone_mode, **extra)

    def _main(self, args: Sequence[str] | None, prog_name: str | None,
              complete_var: str | None, standalone_mode: bool, **extra: Any) -> Any:
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        try:
            code = super().main(args, prog_name, complete_var, False, **extra)
        except UsageError as error:
            if type(error).__name__ == "NoArgsIsHelpError":  # 'pcmapq' alone: click's help
                error.show()  # (the class is new in click 8.2, hence by name, as typer does)
                sys.exit(error.exit_code)
            print(f"pcmapq: error: {usage_message(error)}", file=sys.stderr)
            sys.exit(error.exit_code)
        sys.exit(code if isinstance(code, int) else 0)

    def invoke(self, ctx: typer.Context) -> Any:
        """Click's invoke; an error of the option parser, which names no command, is given
        this group's context (whose ``invoked_subcommand`` says which command failed)."""
        try:
            return super().invoke(ctx)
        except UsageError as error:
            if error.ctx is None:
                error.ctx = ctx
            raise


def usage_message(error: UsageError) -> str:
    """A click usage error as one line: its message, then which --help to read."""
    if isinstance(error, NoSuchOption) and error.possibilities:
        text = f"{error.message}; did you mean {' or '.join(sorted(error.possibilities))}?"
    else:
        text = error.format_message().rstrip(".")
    text = " ".join(text.split())
    if text[:2].istitle():  # "No such option" -> "no such option"; "MAP" stays
        text = text[0].lower() + text[1:]
    ctx = error.ctx
    if ctx is None:
        return text
    command = " ".join(filter(None, (ctx.command_path, ctx.invoked_subcommand)))
    return f"{text} (see '{command} --help')"



@contextmanager
def report_errors(console: Console) -> Iterator[None]:
    """Bad input or a failed evaluation: one line on stderr and the error's exit code."""
    try:
        yield
    except (InputError, EvaluationError) as error:
        console.print(f"pcmapq: error: {error}", markup=False, highlight=False, soft_wrap=True)
        raise typer.Exit(error.exit_code) from None


@contextmanager
def show_warnings(console: Console) -> Iterator[None]:
    """pcmapq's warnings (``warnings.warn`` in pcmapq's code): one line each on stderr, as they
    come, every time. A library's warning (a NumPy RuntimeWarning, ...) is not pcmapq's to
    print: dropped."""
    package = str(Path(__file__).parents[1])  # pcmapq, not pcmapq.cli

    def show(message: Warning | str, category: type[Warning], filename: str, *_: object) -> None:
        if category is UserWarning and filename.startswith(package):
            console.print(f"pcmapq: warning: {message}", markup=False, highlight=False,
                          soft_wrap=True)

    with warnings.catch_warnings():
        warnings.filterwarnings("always", module=r"pcmapq\.")
        warnings.showwarning = show
        yield


@contextmanager
def scan_bar(console: Console, enabled: bool) -> Iterator[Callable[[int, int], None]]:
    """A progress bar over scans on the terminal; nothing when not a terminal."""
    if not (enabled and console.is_terminal):
        yield lambda done, total: None
        return
    with Progress(console=console, transient=True) as bar:
        task = bar.add_task("scans", total=None)
        yield lambda done, total: bar.update(task, completed=done, total=total)


@contextmanager
def step_progress(console: Console, enabled: bool) -> Iterator[Callable[[str], None]]:
    """A spinner on the terminal naming the current step; nothing when not a terminal."""
    if not (enabled and console.is_terminal):
        yield lambda step: None
        return
    with console.status("pcmapq") as status:
        yield lambda step: status.update(f"{step}...")
