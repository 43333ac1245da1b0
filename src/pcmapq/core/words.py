"""Numbers in sentences a user reads: a count with its noun in the right number ("1 point",
"2 points") and a length rounded as metres ("6.6 m"). Every message and report line that
counts or measures uses these, so none reads "1 points" or "6.64829 m"."""

from __future__ import annotations

import math


def plural(n: int, noun: str, many: str | None = None) -> str:
    """``noun`` for one, else its plural: ``many``, or ``noun`` + ``s``."""
    return noun if n == 1 else (many or noun + "s")


def count(n: int, noun: str, many: str | None = None) -> str:
    """``n`` (thousands separated) and its noun in the right number: ``1 point``,
    ``12,345 points``; ``many`` is the plural when not ``noun`` + ``s``."""
    return f"{n:,} {plural(n, noun, many)}"


def length(value: float) -> str:
    """A length in metres for a sentence: two significant digits and never fewer than whole
    metres, ``6.6 m``, ``0.05 m``, ``12 m``, ``250 m`` (no exponent)."""
    if not math.isfinite(value):
        return f"{value} m"
    if value == 0:
        return "0 m"
    decimals = max(0, 1 - math.floor(math.log10(abs(value))))
    text = f"{value:.{decimals}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return f"{text} m"
