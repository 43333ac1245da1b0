"""A real CARMEN log on the command line: pcmapq's own lines on stderr and nothing from its
libraries."""

from __future__ import annotations

import pytest

from testkit.command import foreign_lines
from testkit.paths import shared


def test_a_carmen_log_prints_only_pcmapq_s_lines(capfd: pytest.CaptureFixture[str],
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    log = shared("carmen", "intel-corrected.log.gz")
    code, foreign = foreign_lines(["eval", str(log), str(log)], capfd, monkeypatch)
    assert code == 0 and foreign == []
