"""Counts and lengths in sentences: the noun in the right number, lengths rounded as metres."""

from __future__ import annotations

import math
import re

import pytest

from pcmapq.core.words import count, length, plural
from testkit.paths import REPO


@pytest.mark.parametrize(("n", "text"), [(0, "0 points"), (1, "1 point"), (2, "2 points"),
                                         (12345, "12,345 points")])
def test_a_count_takes_its_noun_in_the_right_number(n, text):
    assert count(n, "point") == text


def test_an_irregular_plural_is_given():
    assert plural(1, "index", "indices") == "index"
    assert count(3, "index", "indices") == "3 indices"


@pytest.mark.parametrize(("value", "text"), [
    (6.64829, "6.6 m"), (0.05, "0.05 m"), (0.123, "0.12 m"), (12.3456, "12 m"),
    (250.0, "250 m"), (4.0, "4 m"), (9.96, "10 m"), (0.0, "0 m"), (-2.345, "-2.3 m"),
    (math.inf, "inf m"),
])
def test_a_length_reads_as_metres_with_two_significant_digits(value, text):
    assert length(value) == text


def test_no_message_puts_a_count_before_a_plural_noun_by_hand():
    """A count of things (``{len(x)}``) before a plural noun reads "1 points" at one: the
    sentences of src/pcmapq say it with :func:`count` or :func:`plural`."""
    by_hand = re.compile(r"\{len\([^}]*\)(:,)?\} [a-z]+s\b")
    found = [f"{path.relative_to(REPO)}:{n}: {line.strip()}"
             for path in sorted((REPO / "src" / "pcmapq").rglob("*.py"))
             for n, line in enumerate(path.read_text().splitlines(), 1) if by_hand.search(line)]
    assert found == []
