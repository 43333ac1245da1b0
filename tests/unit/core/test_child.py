"""A function run in a child process: its result, its exception, and the child's own failure."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pcmapq.core import child
from pcmapq.core.errors import EvaluationError


def test_the_result_comes_back_whole_and_what_the_function_prints_does_not_spoil_it():
    points = np.random.default_rng(0).normal(size=(1000, 3))
    assert np.array_equal(child.in_child("a sum", np.cumsum, points), np.cumsum(points))
    assert child.in_child("a print", print, "to the child's standard error") is None


def test_the_functions_exception_is_raised_here():
    with pytest.raises(ValueError, match="math domain error"):
        child.in_child("a root", math.sqrt, -1.0)


def test_a_child_that_fails_is_one_evaluation_error_naming_the_work(monkeypatch):
    monkeypatch.setattr(child.sys, "executable", "false")
    with pytest.raises(EvaluationError, match=r"^a root's process failed \(exit code 1\)$"):
        child.in_child("a root", math.sqrt, 4.0)
