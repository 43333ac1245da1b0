"""Behaviour unchanged: the shipped sample's result equals the stored reference (numbers within
1e-6), so a refactoring that changes a figure fails here. After a change that is meant to move
the figures, write the reference again (see ``write_reference``) and say why in the commit."""

from __future__ import annotations

import json
from pathlib import Path

from pcmapq.evaluation.pipeline import evaluate
from testkit.paths import REPO
from testkit.reference import differences

REFERENCE = REPO / "tests" / "reference" / "sample.json"


def sample_document() -> dict:
    """The sample's JSON document as the library makes it (no command line)."""
    doc = evaluate(REPO / "data" / "sample" / "scan.ply",
                   REPO / "data" / "sample" / "truth.png").to_dict()
    doc.pop("pcmapq")
    for side in ("map", "truth"):  # the same wherever the repository is
        doc[side]["path"] = Path(doc[side]["path"]).relative_to(REPO).as_posix()
    return json.loads(json.dumps(doc))


def write_reference() -> None:
    """Store the current result as the reference (run by hand, never by a test)."""
    REFERENCE.write_text(json.dumps(sample_document(), indent=1) + "\n")


def test_sample_result_equals_the_reference():
    found = differences(sample_document(), json.loads(REFERENCE.read_text()))
    assert not found, "\n".join(found[:20])
