"""Same place or another place: does pcmapq tell a map of the truth's place from a map of
another place? The former rule (agreement = fitness x truth recall, refused below 0.2), the
confidence (``alignment.confidence``, refused below ``Settings().alignment.min_confidence``)
and the verdict (``alignment.verdict``: below that confidence a map is still scored, as "same
place, inconsistent map", when enough of its parts placed on their own agree with its pose).

Same place: the Intel and Freiburg 079 SLAM maps against their plans and four Halmstad maps
against their layouts (scale estimated), the Gazebo SLAM map against its world, the shipped
sample, CARMEN maps built from drifted poses against the corrected map. Another place: every
CARMEN building against every other (rigid: both in metres), the four Halmstad maps against the
three other layouts, the Intel map against Freiburg's plan and back. Then every Halmstad map
against every layout (the matrix). Runs score with ``force=True`` and no detectors.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from pcmapq.align.parts import PIECES
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.evaluation.same_place import MIN_AGREEING, RECALL_NONE, STANDS_OUT
from pcmapq.report.text import number
from pcmapq.results.result import INCONSISTENT, OTHER, SAME
from testkit.realdata.floorplans import FLOORPLANS
from testkit.realdata.same_place import (
    NEW_MIN_CONFIDENCE,
    PLAN,
    Pair,
    matrix_pairs,
    pairs,
)
from testkit.reference import summary

from .common import Case, Record, Section, header, row, stand_out_rule

#: Former rule: refused below this agreement (the confidence: NEW_MIN_CONFIDENCE).
OLD_MIN_AGREEMENT = 0.2


@dataclass(frozen=True)
class Row:
    """One pair's figures: mode ('rigid' / 'scale'), the search's distinctiveness (None without
    a search), truth recall, fitness, agreement, confidence, seconds, what its reference keeps,
    the verdict, and how many of the map's parts placed on their own agree with its pose and
    how many were placed (0 and 0 when the confidence settled the verdict)."""

    pair: Pair
    mode: str
    distinct: float | None
    recall: float
    fitness: float
    agreement: float
    confidence: float
    seconds: float
    figures: dict
    verdict: str = ""
    agreeing: int = 0
    placed: int = 0

    def summary(self) -> dict:
        return self.figures

    @property
    def old_ok(self) -> bool:
        """Accepted by the former rule (agreement)."""
        return self.agreement >= OLD_MIN_AGREEMENT

    @property
    def new_ok(self) -> bool:
        """Accepted by the confidence."""
        return self.confidence >= NEW_MIN_CONFIDENCE

    @property
    def scored(self) -> bool:
        """Scored by the verdict: "same place" or "same place, inconsistent map"."""
        return self.verdict != OTHER

    @property
    def parts(self) -> str:
        """'k of n' parts agreeing, '-' when the confidence settled the verdict."""
        return f"{self.agreeing} of {self.placed}" if self.placed else "-"


def measure(pair: Pair) -> Row:
    """Run one pair and keep its figures."""
    start = time.perf_counter()
    source = pair.map_source if isinstance(pair.map_source, Path) else pair.map_source()
    result = evaluate(source, pair.truth, pair.settings)
    a, o = result.alignment, result.overlap
    return Row(pair, "scale" if pair.settings.alignment.scale else "rigid", a.distinctiveness,
               o.truth_recall, a.fitness, o.agreement, o.confidence,
               time.perf_counter() - start, summary(result.to_dict()), o.verdict,
               sum(p.agrees for p in o.parts), len(o.parts))


def cases(data: Path) -> list[Case]:
    """The table's pairs, then the matrix's that the table does not hold."""
    table = list(pairs(data))
    seen = {p.case for p in table}
    return [Case(p.case, lambda p=p: measure(p))
            for p in table + [p for p in matrix_pairs(data) if p.case not in seen]]


def _verdict(ok: bool, same: bool) -> str:
    """'accepted' / 'refused', in bold when wrong."""
    word = "accepted" if ok else "refused"
    return word if ok == same else f"**{word}**"


def _named(r: Row) -> str:
    """The row's verdict, in bold when wrong (a same-place map refused, another place
    scored)."""
    return r.verdict if r.scored == r.pair.same else f"**{r.verdict}**"


def table(rows: list[Row]) -> str:
    """The table, and how many pairs each rule gets wrong."""
    lines = [header(["pair", "place", "search", "fitness", "truth recall", "agreement (before)",
                     "distinctiveness", "confidence (after)", "before", "after", "verdict",
                     "parts agreeing", "s"])]
    for r in rows:
        lines.append(row([
            r.pair.name, "same" if r.pair.same else "other", r.mode, number(r.fitness, 2),
            *(number(v, 2) for v in (r.recall, r.agreement, r.distinct, r.confidence)),
            _verdict(r.old_ok, r.pair.same), _verdict(r.new_ok, r.pair.same), _named(r),
            r.parts, f"{r.seconds:.1f}"]))
    return "\n".join(lines + ["", verdicts(rows)])


def verdicts(rows: list[Row]) -> str:
    """One line: wrong verdicts of each rule among same-place and other-place pairs."""
    same = [r for r in rows if r.pair.same]
    other = [r for r in rows if not r.pair.same]
    return (f"{len(same)} same-place pairs: refused before {sum(not r.old_ok for r in same)}, "
            f"after {sum(not r.new_ok for r in same)}, by the verdict "
            f"{sum(not r.scored for r in same)}; {len(other)} other-place pairs: "
            f"accepted before {sum(r.old_ok for r in other)}, after "
            f"{sum(r.new_ok for r in other)}, scored by the verdict "
            f"{sum(r.scored for r in other)}.")


def figures(r: Row) -> str:
    """'name (distinctiveness d, recall r, confidence c, verdict v, k of n parts agreeing)'."""
    parts = "" if not r.placed else f", {r.agreeing} of {r.placed} parts agreeing"
    return (f"{r.pair.name} (distinctiveness {number(r.distinct, 2)}, recall "
            f"{number(r.recall, 2)}, confidence {number(r.confidence, 2)}, "
            f"\"{r.verdict}\"{parts})")


def rules(r: Row) -> str:
    """'same place; confidence accepted, verdict refused', the wrong ones in bold."""
    def word(ok: bool, yes: str, no: str) -> str:
        said = yes if ok else no
        return said if ok == r.pair.same else f"**{said}**"

    return (f"{'same' if r.pair.same else 'another'} place; confidence "
            f"{word(r.new_ok, 'accepts', 'refuses')}, verdict "
            f"{word(r.scored, 'scores', 'refuses')}")


def section(data: Path, record: Record) -> Section:
    """The table, what it shows, and the matrix's summary."""
    measured = {c.name: c.run(record) for c in cases(data)}
    rows = [measured[p.case] for p in pairs(data)]
    grid = [replace(measured[p.case], pair=p) for p in matrix_pairs(data)]
    same, other = [r for r in rows if r.pair.same], [r for r in rows if not r.pair.same]
    thin = min((r for r in same if r.new_ok), key=lambda r: r.confidence)
    top = max(other, key=lambda r: r.confidence)
    low = [r for r in same if not r.new_ok]
    scored_other = [figures(r) for r in other if r.scored]
    wrong = [r for r in grid if r.new_ok != r.pair.same or r.scored != r.pair.same]
    g_same, g_other = [r for r in grid if r.pair.same], [r for r in grid if not r.pair.same]
    parts = PIECES[0] * PIECES[1]

    def share(rows: list[Row], ok: Callable[[Row], bool]) -> str:
        return f"{100 * sum(ok(r) for r in rows) / len(rows):.0f} %"

    return Section("\n".join([
        "## Same place or another place: the confidence, before and after", "",
        "Every pair is scored with `force` and no detectors (`tests/realdata/test_same_place.py` "
        "checks some of these pairs); \"before\" is the former rule (refused when fitness x truth "
        f"recall < {OLD_MIN_AGREEMENT}), \"after\" the confidence of `docs/method.md` "
        f"(refused below {NEW_MIN_CONFIDENCE}), \"verdict\" the result's "
        f"`alignment.verdict`: \"{SAME}\" at confidence {NEW_MIN_CONFIDENCE} or more; below it "
        f"\"{INCONSISTENT}\" when at least {MIN_AGREEING} of the map's {parts} parts, each "
        "placed on its own by the global search, land near the map's pose (\"parts "
        "agreeing\"; \"-\" when the confidence settled the verdict), or when its pose's "
        f"distinctiveness is at least {STANDS_OUT} with a truth recall above {RECALL_NONE}, "
        f"else \"{OTHER}\", "
        "refused unless forced. A wrong verdict is in bold. "
        "Same place: the Intel map through `--map-occupied-thresh "
        f"{FLOORPLANS[0].thresholds.occupied} --map-free-thresh "
        f"{FLOORPLANS[0].thresholds.free}`, every plan and layout at {PLAN.truth.resolution} m "
        "per pixel with the scale estimated (\"scale\"), CARMEN maps built from drifted poses "
        "(seed 0) against the corrected map. Another place: every CARMEN building's map "
        "against every other's (both metric: \"rigid\"), the Halmstad maps against the other "
        "layouts, and the Intel and Freiburg 079 maps against each other's plan. Times are "
        "with detectors off.", "",
        table(rows), "",
        f"The confidence accepts {sum(r.new_ok for r in same)} of the {len(same)} same-place "
        f"pairs, the thinnest margin being {figures(thin)}"
        + ("" if thin.distinct is None else f": the best pose far from the chosen one scores "
           f"{100 * thin.distinct:.0f} % less in the search") + ". It refuses "
        f"{sum(not r.new_ok for r in other)} of the {len(other)} other-place pairs; the "
        f"largest confidence among them: {figures(top)}. Same-place pairs below the minimum "
        "confidence: " + ("; ".join(figures(r) for r in low) if low else "none") + "."
        + (f" The verdict scores {sum(r.scored for r in low)} of them as \"{INCONSISTENT}\": "
           "no one pose fits such a map whole, yet its parts, placed on their own, land where "
           "its pose puts them." if any(r.scored for r in low) else "")
        + " Other-place pairs the verdict scores: "
        + ("; ".join(scored_other) if scored_other else "none") + ".", "",
        f"Every Halmstad map against every layout ({len(grid)} pairs), where same-looking office "
        f"floors make the hardest case: {verdicts(grid)} Pairs that the confidence or the "
        "verdict gets wrong (the wrong one in bold):", "",
        *(f"- {figures(r)}: {rules(r)}" for r in wrong), "",
        f"So on this matrix the former rule accepted {share(g_other, lambda r: r.old_ok)} of "
        f"the other-place pairs, the confidence accepts {share(g_other, lambda r: r.new_ok)} "
        f"and the verdict scores {share(g_other, lambda r: r.scored)} "
        f"({sum(r.scored for r in g_other)} of {len(g_other)}), while the confidence refuses "
        f"{sum(not r.new_ok for r in g_same)} of the {len(g_same)} same-place maps and the "
        f"verdict {sum(not r.scored for r in g_same)}: geometry alone cannot always tell one "
        "office floor from another.", "",
        _most_distinct(g_other),
    ]))


def _most_distinct(other: list[Row]) -> str:
    """The sentence on the other-place pose that stands out most: the margin of the verdict's
    STANDS_OUT rule."""
    searched = [r for r in other if r.distinct is not None]
    if not searched:
        return ""
    top = max(searched, key=lambda r: r.distinct)
    return (f"The other-place pose that stands out most in its search: {figures(top)}. "
            f"{stand_out_rule()}")
