"""How a figure reads wherever it is shown: a number, `n/a` for an undefined score, `-` for
nothing measured."""

from __future__ import annotations


def score(value: float | None, digits: int = 3) -> str:
    """A quality, precision or f1 with ``digits`` decimals; 'n/a' when undefined (nothing to
    count, see :mod:`pcmapq.match`)."""
    return "n/a" if value is None else f"{value:.{digits}f}"


def number(value: float | None, digits: int = 3) -> str:
    """A figure with ``digits`` decimals; '-' when there is none (nothing measured)."""
    return "-" if value is None else f"{value:.{digits}f}"
