"""The result's one schema: docs/result.schema.json is generated from the models that write
and read the JSON, a result validates against it with an independent validator, a document
that strays from it is refused, and every kind of block reads back byte for byte."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from pydantic import ValidationError

from pcmapq.results import schema
from pcmapq.results.blocks import rounded
from pcmapq.results.figures import figures
from pcmapq.results.gates import check, parse_rules, with_gates
from pcmapq.results.result import Result
from testkit.paths import REPO

jsonschema = pytest.importorskip("jsonschema")


@pytest.fixture(scope="module")
def doc(sample_result) -> dict:
    return sample_result.to_dict()


def _text(doc: dict) -> str:
    return json.dumps(doc, indent=2, allow_nan=False) + "\n"


def test_the_published_schema_is_current():
    assert (REPO / "docs" / "result.schema.json").read_text() == schema.schema_text(), \
        "run python tools/options_doc.py"


def test_a_result_follows_the_published_schema(doc: dict):
    published = json.loads((REPO / "docs" / "result.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(published)
    jsonschema.validate(doc, published, cls=jsonschema.Draft202012Validator)
    gated = with_gates(doc, check(parse_rules("harris.quality=0.5", "accuracy.mean=0.2"), doc))
    jsonschema.validate(gated, published, cls=jsonschema.Draft202012Validator)


@pytest.mark.parametrize("change", ["unknown key", "missing key", "word for a number"])
def test_a_document_off_the_schema_is_refused(doc: dict, change: str):
    bad = copy.deepcopy(doc)
    if change == "unknown key":
        bad["alignment"]["fitnes"] = 0.5
    elif change == "missing key":
        del bad["detectors"]["harris"]["matched"]
    else:
        bad["coverage"] = "most"
    with pytest.raises(ValidationError) as error:
        Result.from_json(_text(bad))
    assert isinstance(error.value, ValueError)
    published = json.loads((REPO / "docs" / "result.schema.json").read_text())
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, published, cls=jsonschema.Draft202012Validator)


def _full(doc: dict) -> dict:
    """The sample's document with the blocks it lacks: a recording's message, a 3D
    registration, its distances and map figures, gates; no truth digest."""
    full = copy.deepcopy(doc)
    full["map"].update(topic="/map", index=2, time_s=10.5, stamp_s=None)
    del full["truth"]["sha256"]
    full["alignment_3d"] = {"matrix": [[1.0, 0.0, 0.0, 0.5], [0.0, 1.0, 0.0, 0.0],
                                       [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
                            "fitness": 0.9, "rmse_m": 0.02}
    full["distances_3d"] = {**copy.deepcopy(full["distances"]), "computed_on": "points"}
    full["map_3d"] = {"computed_on": "3 m voxels", "voxels": 12, "awd_m": 0.05, "scs": None}
    full["rooms"] = full.pop("rooms")  # written after the 3D blocks
    return with_gates(full, check(parse_rules("harris.quality=0.5", None), full))


def test_every_block_reads_back_through_the_schema_byte_for_byte(doc: dict):
    for saved in (doc, _full(doc)):
        read = schema.ResultDocument.model_validate_json(_text(saved))
        written = {**rounded(read.model_dump(exclude_unset=True)), "noref": read.noref}
        assert _text(written) == _text(saved)


def test_a_result_read_back_has_the_saved_figures(doc: dict):
    """Every figure of a result read back is the saved one; the only numbers written again
    otherwise are those recomputed from rounded coordinates (a match's length from its two
    rounded ends, a tilt from its rounded matrix): within 3e-5 of the saved ones."""
    for saved in (doc, {k: v for k, v in _full(doc).items() if k != "gates"}):
        back = Result.from_json(_text(saved))
        assert back.figures() == figures(saved)
        again = back.to_dict()
        assert again.keys() == saved.keys()
        assert [m["displacement_m"] for m in again["matches"]] == pytest.approx(
            [m["displacement_m"] for m in saved["matches"]], abs=1.01e-6)
        assert again["frames"]["map_levelling"]["tilt_deg"] == pytest.approx(
            saved["frames"]["map_levelling"]["tilt_deg"], abs=3e-5)


def test_an_older_result_without_later_keys_reads_back(doc: dict):
    """Keys added since (poses, contradiction, seen_through, the consistency map) may be
    absent: the result reads back without them and writes them as it read them."""
    old = copy.deepcopy(doc)
    for key in ("poses", "contradiction", "free_on_truth", "seen_through"):
        del old["alignment"][key]
    del old["consistency"]
    back = Result.from_json(_text(old))
    assert back.alignment.poses == () and back.consistency is None
    assert back.overlap.seen_through is None


def test_the_saved_sample_reference_names_only_schema_keys():
    """tests/reference/sample.json keeps a subset of a result's keys: each is in the schema."""
    saved = json.loads((Path(REPO) / "tests" / "reference" / "sample.json").read_text())
    fields = schema.ResultDocument.model_fields
    assert set(saved) <= set(fields)
    for key in ("alignment", "distances", "truth", "map"):
        block = fields[key].annotation
        assert set(saved[key]) <= set(block.model_fields), key
