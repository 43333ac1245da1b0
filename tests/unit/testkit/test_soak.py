"""The soak's checks (testkit.soak): each leak is named."""

from __future__ import annotations

import pytest

from testkit import soak


def test_soak_failures_name_each_leak() -> None:
    got = soak.Soak(["a", "b"], runs=6, seconds=[1.0] * 6,
                    rss_mb=[100.0, 100.0, 104.0, 104.0, 109.0, 112.0],
                    mismatches=[("b", 3)], unexpected=["a"])
    got.census = {"start": soak.Census(1, 4, 7), "first round": soak.Census(1, 6, 7),
                  "end": soak.Census(2, 8, 9)}
    assert got.rounds == 3 and got.growth() == pytest.approx(0.12)
    fails = got.failures()
    assert len(fails) == 6, fails
    assert "a: unexpected outcome" in fails
    assert "run 3 (b): outcome differs from the first run" in fails
    assert any(f.startswith("RSS grew 12.0 %") for f in fails)
    assert "Python threads 1 -> 2" in fails
    assert any(f.startswith("OS threads 6") for f in fails)
    assert any(f.startswith("open file descriptors 7") for f in fails)
    got.rss_mb[-1], got.census["end"] = 109.0, soak.Census(1, 6, 7)
    got.mismatches, got.unexpected = [], []
    assert got.failures() == []
