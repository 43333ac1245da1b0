"""The corpus's section of docs/validation.md as bench's command line writes it from saved
records (``python -m bench.validation.corpus --records FILE``): the worst other-place pair, the
ROC's safe threshold, the pairs that go wrong. Tests reach bench/ only through its command
lines, in a subprocess."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from testkit.corpus import Record
from testkit.corpus.examples import RECORDS, VERDICTS
from testkit.paths import REPO


def markdown(records: list[Record], folder: Path, fields: tuple[str, ...] = ("confidence",)
             ) -> str:
    """What ``python -m bench.validation.corpus --records`` prints for ``records`` (the
    section's markdown, its ROC of ``fields``)."""
    path = folder / "records.jsonl"
    path.write_text("".join(r.to_json() + "\n" for r in records))
    got = subprocess.run([sys.executable, "-m", "bench.validation.corpus", "--records", str(path),
                          "--fields", ",".join(fields)], cwd=REPO, capture_output=True, text=True,
                         timeout=300)
    assert got.returncode == 0, got.stderr
    return got.stdout


def test_markdown_names_the_worst_other_place(tmp_path: Path) -> None:
    text = markdown(RECORDS, tmp_path, ("confidence", "truth_recall"))
    assert "Worst other-place pair: o3 (confidence 0.55" in text
    assert "| 0.56 (lowest with no other place, confidence) | 67 % | 0 % | - | - |" in text


def test_markdown_names_the_pairs_that_go_wrong(tmp_path: Path) -> None:
    text = markdown(VERDICTS, tmp_path)
    assert text.startswith("## Same place, inconsistent map, or another place: a labelled "
                           "corpus")
    assert "6 pairs of a map and a truth" in text  # the dropped one left out
    assert "1 of the 1 synthetic other-place pairs were dropped" in text
    assert "Real other places scored: 0 of 1." in text
    assert ("Same place refused (\"another place\"): 1 of 4:\n- bend b 1: \"another place\", "
            "confidence 0.10, 1 of 8 parts agreeing") in text
    assert ("Another place scored: 1 of 2:\n- layout p vs q: \"same place, inconsistent map\", "
            "confidence 0.20, 2 of 8 parts agreeing, largest offset 0.50 m") in text
    assert "bend: 0.15, 0.80 m at 0.2, 1 m of the far corner (grows with the level)" in text
    assert "| bend | 1 | same | 2 | **1 (50 %)** | 1 | 0 | 0.20 | 0.80 |" in text
