"""Pass/fail gates (--fail-under, --fail-over): parsing, resolving keys against a result's JSON,
and the verdict (exit code 3 on the command line: tests/cli/test_gates.py)."""

from __future__ import annotations

import json

import pytest

from pcmapq.results import gates
from pcmapq.results.gates import (
    OVER,
    UNDER,
    Gate,
    GateError,
    check,
    failures,
    json_path,
    parse_gates,
)

#: A small result document with the JSON's shape (the figures made up, the layout real).
DOC = {
    "coverage": 0.9,
    "alignment": {"confidence": 1.0, "fitness": 0.8, "rmse_m": 0.04, "method": "coarse+icp"},
    "distances": {"accuracy_m": {"count": 10, "mean": 0.12, "median": 0.05},
                  "completeness_m": {"count": 8, "mean": None, "median": None},
                  "chamfer_m": 0.08,
                  "f_score": [{"tau_m": 0.05, "f": 0.6}, {"tau_m": 0.1, "f": 0.7}]},
    "detectors": {"harris": {"quality": 0.75, "precision": None, "f1": None,
                             "note": "no strong map feature", "truth_features": 4},
                  "sift": {"quality": 1.0, "precision": 0.5, "f1": 0.666667, "note": None}},
    "footprint": "walls", "flag": True,
}


def test_parse_reads_pairs_in_order():
    assert parse_gates(" harris.quality=0.8, accuracy.mean = 5e-2", UNDER) == [
        Gate("harris.quality", 0.8, UNDER), Gate("accuracy.mean", 0.05, UNDER)]
    assert parse_gates("chamfer=1", OVER)[0].option == "--fail-over"
    assert parse_gates(None, OVER) == []


@pytest.mark.parametrize(("text", "words"), [
    ("harris.quality", "expected KEY=VALUE"),
    ("harris.quality=0.8,", "expected KEY=VALUE"),
    ("=0.8", "expected KEY=VALUE"),
    ("harris.quality=abc", "finite number, got 'abc'"),
    ("harris.quality=nan", "finite number"),
    ("harris.quality=inf", "finite number"),
    ("harris.qualty=0.8", "did you mean harris.quality"),
    ("bogus=1", "unknown key 'bogus'"),
    ("detectors..harris=1", "unknown key"),
    ("f_score@abc=1", "f_score@TAU"),
    ("f_score@-0.1=1", "f_score@TAU"),
])
def test_parse_refuses_in_one_line_naming_the_option(text, words):
    with pytest.raises(GateError) as caught:
        parse_gates(text, UNDER)
    message = str(caught.value)
    assert words in message and message.startswith("--fail-under") and "\n" not in message
    assert caught.value.exit_code == 2


@pytest.mark.parametrize(("key", "path"), [
    ("harris.quality", ("detectors", "harris", "quality")),
    ("sift.f1", ("detectors", "sift", "f1")),
    ("hough.precision", ("detectors", "hough", "precision")),
    ("accuracy.mean", ("distances", "accuracy_m", "mean")),
    ("completeness.median", ("distances", "completeness_m", "median")),
    ("accuracy_3d.p95", ("distances_3d", "accuracy_m", "p95")),
    ("awd_3d", ("map_3d", "awd_m")),
    ("scs_3d", ("map_3d", "scs")),
    ("chamfer", ("distances", "chamfer_m")),
    ("chamfer.mean", ("distances", "chamfer_m")),
    ("f_score@0.1", ("distances", "f_score", 1, "f")),
    ("coverage", ("coverage",)),
    ("alignment.rmse_m", ("alignment", "rmse_m")),
    ("distances.f_score.0.f", ("distances", "f_score", 0, "f")),
    ("detectors.sift.displacement_m.p95", ("detectors", "sift", "displacement_m", "p95")),
])
def test_keys_name_their_json_path(key, path):
    assert json_path(key, DOC) == path


def test_check_judges_each_bound_inclusively():
    rules = parse_gates("harris.quality=0.75,sift.quality=1.01,coverage=0.9", UNDER) + \
        parse_gates("accuracy.mean=0.1,chamfer=0.08,f_score@0.05=0.5", OVER)
    got = [(o.path, o.value, o.passed) for o in check(rules, DOC)]
    assert got == [("detectors.harris.quality", 0.75, True),
                   ("detectors.sift.quality", 1.0, False),
                   ("coverage", 0.9, True),
                   ("distances.accuracy_m.mean", 0.12, False),
                   ("distances.chamfer_m", 0.08, True),
                   ("distances.f_score.0.f", 0.6, False)]


def test_failures_name_the_figure_its_value_and_the_bound():
    rules = parse_gates("sift.quality=1.01", UNDER) + parse_gates("accuracy.mean=0.1", OVER)
    assert failures(rules, DOC) == [
        "sift.quality = 1.0, under the bound 1.01 (--fail-under)",
        "accuracy.mean = 0.12 m, over the bound 0.1 m (--fail-over)"]
    assert failures(parse_gates("coverage=0.5", UNDER), DOC) == []


def test_a_null_figure_fails_its_gate_saying_why():
    under = check(parse_gates("harris.precision=0", UNDER), DOC)[0]
    over = check(parse_gates("completeness.mean=100", OVER), DOC)[0]
    assert (under.value, under.passed, over.value, over.passed) == (None, False, None, False)
    assert under.line() == ("harris.precision is n/a (nothing to measure: no strong map "
                            "feature), so it fails its bound 0.0 (--fail-under)")
    assert "n/a (nothing to measure)" in over.line()


@pytest.mark.parametrize(("key", "words"), [
    ("hough.quality", "no 'hough' in detectors (it has: harris, sift)"),
    ("detectors.sift.nope", "no 'nope' in detectors.sift"),
    ("distances.f_score.5.f", "no 5 in distances.f_score (it has: items 0 to 1)"),
    ("alignment.method", "alignment.method is 'coarse+icp', not a number"),
    ("detectors.sift", "detectors.sift is a group, not a number"),
    ("footprint", "footprint is 'walls', not a number"),
    ("f_score", "name one: f_score@0.05, f_score@0.1"),
    ("f_score@0.2", "no F-score at that tau"),
    ("f_score_3d@0.1", "no 3D distances"),
    ("accuracy_3d.mean", "no 'distances_3d' in the top level"),
    ("awd_3d", "no 'map_3d' in the top level"),
])
def test_a_key_the_result_lacks_is_a_usage_error(key, words):
    rules = parse_gates(f"{key}=1", OVER)
    with pytest.raises(GateError) as caught:
        check(rules, DOC)
    assert words in str(caught.value) and str(caught.value).startswith("--fail-over")


def test_a_boolean_is_not_a_number():
    with pytest.raises(GateError, match="flag is True, not a number"):
        check([Gate("flag", 1.0, UNDER)], DOC)


def test_a_single_f_score_needs_no_tau():
    doc = {"distances": {"f_score": [{"tau_m": 0.2, "f": 0.4}]}}
    assert check(parse_gates("f_score=0.5", UNDER), doc)[0].value == 0.4


def test_the_gates_block_is_added_last_and_nothing_else_changes():
    outcomes = check(parse_gates("coverage=0.95", UNDER), DOC)
    doc = gates.with_gates(DOC, outcomes)
    assert list(doc)[:-1] == list(DOC) and all(doc[k] == DOC[k] for k in DOC)
    assert doc["gates"] == [{"key": "coverage", "path": "coverage", "option": "--fail-under",
                             "bound": 0.95, "value": 0.9, "passed": False}]
    assert gates.to_json(doc) == json.dumps(doc, indent=2, allow_nan=False) + "\n"
