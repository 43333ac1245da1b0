"""Stored references (testkit.reference): the comparison of two JSON documents sees a
change, and a reference keeps the named fields only."""

from __future__ import annotations

import json

from testkit import reference
from testkit.paths import REPO
from testkit.reference import differences

REFERENCE = REPO / "tests" / "reference" / "sample.json"


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


def test_a_reference_keeps_named_fields_only():
    """New fields of the JSON document do not change the summary a reference stores."""
    doc = json.loads((REPO / "tests" / "reference" / "sample.json").read_text())
    kept = reference.summary(doc)
    assert set(kept) == {"alignment", "coverage", "footprint", "distances", "detectors"}
    assert set(kept["detectors"]["sift"]) == {"quality", "precision", "f1", "truth_features",
                                              "map_features", "matched"}
    doc["alignment"]["new_figure"] = 1.0
    doc["detectors"]["sift"]["new_figure"] = 2.0
    doc["new_section"] = {"x": 3}
    assert reference.summary(doc) == kept
    assert reference.differences(kept, kept) == []
