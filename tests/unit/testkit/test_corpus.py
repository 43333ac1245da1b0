"""The labelled corpus (testkit.corpus): the ROC, acceptance and verdict analysis on
hand-made records with known answers, the screening's shared walls, and the corpus's make-up
(listed, not measured)."""

from __future__ import annotations

import numpy as np
import pytest

from testkit import corpus, synth
from testkit.corpus.examples import RECORDS, VERDICTS, record
from testkit.paths import SHARED_DATA


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


def test_corpus_make_up() -> None:
    """At least 150 pairs with unique names and both labels, synthetic ones alone included;
    every synthetic other place, and only those, is screened; nothing is built or scored."""
    pairs = corpus.pairs(SHARED_DATA)
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
    others = [p for p in pairs if not p.same]
    assert {p.kind for p in others if p.screen} == set(corpus.SYNTHETIC_OTHER)
    assert all((p.screen is not None) == (p.kind in corpus.SYNTHETIC_OTHER) for p in pairs)
    assert "other synthetic" not in corpus.KINDS
    # no synthetic other place sets a plan against another of its size
    for p in others:
        if p.screen is not None:
            a, b = p.screen
            assert a.rooms or b.rooms or (a.width, a.height) != (b.width, b.height), p.name


def test_other_layouts_differ_from_the_plans() -> None:
    """Each other layout against the plan it is set against: another outline, corridor walls
    at other heights, room walls at other places along the corridor."""
    def walls(segments: np.ndarray) -> tuple[set, set]:
        flat = {round(y0, 2) for x0, y0, x1, y1 in segments if abs(y0 - y1) < 1e-9}
        upright = {round(x0, 2) for x0, y0, x1, y1 in segments if abs(x0 - x1) < 1e-9}
        return flat, upright

    for p in corpus.synthetic_pairs():
        if p.kind != "other layout":
            continue
        layout, plan = p.screen
        assert (layout.width, layout.height) != (plan.width, plan.height)
        (flat_a, up_a), (flat_b, up_b) = walls(layout.segments()), walls(plan.segments())
        # building_plan's corridor: 2.2 m wide, its lower wall at 0.42 of the height
        corridor_a = {round(0.42 * layout.height, 2), round(0.42 * layout.height + 2.2, 2)}
        corridor_b = {round(0.42 * plan.height, 2), round(0.42 * plan.height + 2.2, 2)}
        assert corridor_a <= flat_a and corridor_b <= flat_b
        assert not corridor_a & flat_b and not corridor_b & flat_a, p.name
        inner_a, inner_b = up_a - {0.0, layout.width}, up_b - {0.0, plan.width}
        assert len(inner_a & inner_b) <= 2, p.name


def test_shared_walls() -> None:
    """A plan shares all its walls with itself; plans 0 and 1 (one size) share most of theirs
    where they lie (more than the screening allows); the round rooms little."""
    plan0 = corpus.wall_samples(synth.building_plan(0))
    assert corpus.shared(plan0, plan0) == 1.0
    plan1 = corpus.wall_samples(synth.building_plan(1))
    assert corpus.shared(plan0, plan1) > 0.8 > corpus.MAX_SHARED
    assert corpus.shared(corpus.wall_samples(synth.round_rooms()), plan0) < corpus.MAX_SHARED
    assert corpus.Screened(0.4, 0.31, 1.0).dropped and not corpus.Screened(0.4, 0.3, 1.0).dropped


def test_verdict_groups() -> None:
    groups = {(g.kind, g.level): g for g in corpus.verdict_groups(corpus.kept(VERDICTS))}
    low, high = groups["bend", 0.2], groups["bend", 1.0]
    assert (low.pairs, low.scored, low.inconsistent, low.accepted) == (2, 2, 0, 2)
    assert low.offset == pytest.approx(0.15)
    assert (high.pairs, high.scored, high.inconsistent, high.accepted) == (2, 1, 1, 0)
    assert high.offset == 0.8 and high.share == 0.5
    layout = groups["other layout", "30 x 12 m"]
    assert (layout.pairs, layout.scored, layout.inconsistent) == (1, 1, 1)
    assert corpus.rising([0.15, 0.8]) and not corpus.rising([0.15, None])
    assert not corpus.rising([0.8, 0.15])
