"""Behaviour unchanged: the shipped sample's result equals the stored reference (numbers within
1e-6), so a refactoring that changes a figure fails here. After a change that is meant to move
the figures, write the reference again (see ``write_reference``) and say why in the commit."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bench.validation.reference import differences
from pcmapq.evaluation.pipeline import evaluate

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "tests" / "reference" / "sample.json"


def sample_document() -> dict:
    """The sample's JSON document as the library makes it (no command line)."""
    doc = evaluate(ROOT / "data" / "sample" / "scan.ply",
                   ROOT / "data" / "sample" / "truth.png").to_dict()
    doc.pop("pcmapq")
    for side in ("map", "truth"):  # the same wherever the repository is
        doc[side]["path"] = Path(doc[side]["path"]).relative_to(ROOT).as_posix()
    return json.loads(json.dumps(doc))


def write_reference() -> None:
    """Store the current result as the reference (run by hand, never by a test)."""
    REFERENCE.write_text(json.dumps(sample_document(), indent=1) + "\n")


@pytest.mark.e2e  # whole evaluations
def test_sample_result_equals_the_reference():
    found = differences(sample_document(), json.loads(REFERENCE.read_text()))
    assert not found, "\n".join(found[:20])


def test_the_comparison_sees_a_change():
    doc = json.loads(REFERENCE.read_text())
    moved = json.loads(json.dumps(doc))
    moved["alignment"]["x_m"] += 2e-6
    assert differences(moved, doc) == [f".alignment.x_m: {moved['alignment']['x_m']} != "
                                       f"{doc['alignment']['x_m']}"]
    assert differences(doc, doc) == []
    gone = json.loads(json.dumps(doc))
    del gone["alignment"]["fitness"]
    assert differences(gone, doc) == [".alignment: keys ['fitness'] gone"]
    gone["alignment"]["new_field"] = 1.0  # a field the reference lacks is no change
    gone["alignment"]["fitness"] = doc["alignment"]["fitness"]
    assert differences(gone, doc) == []
