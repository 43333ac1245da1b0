"""bench/validation/corpus.py: the ROC and acceptance analysis on hand-made records with known
answers, and the corpus's make-up (listed, not measured)."""

from __future__ import annotations

import pytest

from bench.validation import corpus
from bench.validation.common import DATA


def record(name: str, same: bool, confidence: float | None, kind: str = "k",
           level: float | None = 1.0, **alignment: float) -> corpus.Record:
    block = {} if confidence is None else {"confidence": confidence, **alignment}
    return corpus.Record(name, kind, level, same, "points", alignment=block)


#: 3 same-place pairs (0.9, 0.6, 0.3) and 3 other-place pairs (0.0, 0.2, 0.55).
RECORDS = [record("s1", True, 0.9, truth_recall=0.2), record("s2", True, 0.6, truth_recall=0.5),
           record("s3", True, 0.3, truth_recall=0.9),
           record("o1", False, 0.0, "o", truth_recall=0.1),
           record("o2", False, 0.2, "o", truth_recall=0.3),
           record("o3", False, 0.55, "o", truth_recall=0.4)]


def test_roc_shares() -> None:
    points = {p.threshold: p for p in corpus.roc(RECORDS)}
    assert (points[0.0].same, points[0.0].other) == (1.0, 1.0)
    assert (points[0.3].same, points[0.3].other) == (1.0, pytest.approx(1 / 3))
    assert (points[0.5].same, points[0.5].other) == (pytest.approx(2 / 3), pytest.approx(1 / 3))
    assert (points[0.56].same, points[0.56].other) == (pytest.approx(2 / 3), 0.0)
    assert (points[0.91].same, points[0.91].other) == (0.0, 0.0)


def test_lowest_threshold_with_no_other_place() -> None:
    best = corpus.safe(RECORDS)
    assert best is not None and best.threshold == 0.56
    assert best.same == pytest.approx(2 / 3) and best.other == 0.0
    # another figure by name: truth recall separates the other way round
    by_recall = corpus.safe(RECORDS, "truth_recall")
    assert by_recall is not None and by_recall.threshold == 0.41
    assert by_recall.same == pytest.approx(2 / 3)
    # an other-place pair at 1.0: no threshold of [0, 1] refuses it
    assert corpus.safe([*RECORDS, record("o4", False, 1.0)]) is None


def test_missing_figure_is_refused() -> None:
    failed = record("f", True, None)
    assert corpus.value(failed, "confidence") is None and not corpus.accepted(failed, 0.0)
    points = corpus.roc([failed, RECORDS[0]], thresholds=(0.0,))
    assert points[0].same == 0.5 and points[0].other == 0.0


def test_acceptance_per_kind_and_level() -> None:
    groups = {(g.kind, g.level): g for g in corpus.acceptance(RECORDS, 0.5)}
    same, other = groups["k", 1.0], groups["o", 1.0]
    assert (same.pairs, same.accepted, same.median, same.low, same.high) == (3, 2, 0.6, 0.3, 0.9)
    assert (other.pairs, other.accepted, other.median) == (3, 1, 0.2)
    assert [r.name for r in corpus.pose_wrong([
        corpus.Record("p", "k", 1.0, True, "points", pose_error_m=1.5, yaw_error_deg=0.0),
        corpus.Record("q", "k", 1.0, True, "points", pose_error_m=0.1, yaw_error_deg=6.0),
        corpus.Record("r", "k", 1.0, True, "points", pose_error_m=0.1, yaw_error_deg=1.0),
        corpus.Record("s", "k", 1.0, False, "points", pose_error_m=9.0, yaw_error_deg=9.0),
    ])] == ["p", "q"]


def test_markdown_names_the_worst_other_place() -> None:
    text = corpus.markdown(RECORDS, ("confidence", "truth_recall"))
    assert "Worst other-place pair: o3 (confidence 0.55" in text
    assert "| 0.56 (lowest with no other place, confidence) | 67 % | 0 % | - | - |" in text


def test_corpus_make_up() -> None:
    """At least 150 pairs with unique names and both labels, synthetic ones alone included;
    nothing is built or scored."""
    pairs = corpus.pairs(DATA)
    names = [p.name for p in pairs]
    assert len(pairs) >= 150 and len(set(names)) == len(names)
    assert {p.same for p in pairs} == {True, False}
    assert all(p.kind in corpus.KINDS and callable(p.build_map) and callable(p.build_truth)
               for p in pairs)
    synthetic = list(corpus.synthetic_pairs())
    assert len(synthetic) >= 150 and {p.same for p in synthetic} == {True, False}
    for kind in ("noise", "missing walls", "bend", "clutter", "broken half"):
        ladder = [p for p in synthetic if p.kind == kind]
        assert len({p.level for p in ladder}) >= 3 and len(ladder) >= 9
    assert corpus.bend_rate(1.0) == pytest.approx(0.0828, abs=1e-4)
