"""Scoring the labelled corpus of "same place, another place" (its pairs and their analysis:
:mod:`testkit.corpus`) and its section of docs/validation.md.

    python -m bench.validation.corpus --out bench/results/corpus.jsonl [--data DIR]
        [--only TEXT] [--fields confidence,truth_recall] [--records FILE] [--list]

``python -m bench.validation --only corpus`` runs it as a section of docs/validation.md (its
records in the system's temporary folder, ``pcmapq-corpus.jsonl``).
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import tempfile
import time
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from pcmapq.align.parts import PIECES
from pcmapq.core.transform import Similarity2D
from pcmapq.evaluation.pipeline import evaluate
from pcmapq.evaluation.same_place import (
    MIN_AGREEING,
    ON_TRUTH,
    RECALL_NONE,
    SEEN_THROUGH,
    STANDS_OUT,
)
from pcmapq.report.text import number
from pcmapq.results.result import INCONSISTENT, LOW, OTHER, SAME
from testkit.corpus import (
    CURRENT,
    DRIFT_LOGS,
    DRIFT_SCANS,
    KINDS,
    MAX_SHARED,
    RESOLUTION,
    SHARED_M,
    SHARED_STEP,
    SPACING,
    SYNTHETIC_OTHER,
    THICKNESS,
    Pair,
    Record,
    accepted,
    agreeing,
    kept,
    load,
    offsets,
    pairs,
    pose_wrong,
    rising,
    roc,
    safe,
    scored,
    screen,
    value,
    verdict_groups,
)
from testkit.corpus.records import _kind_key

from .common import DATA, ROOT, Case, Section, header, row, stand_out_rule
from .common import Record as Figures

#: Where ``python -m bench.validation --only corpus`` writes its records (to analyse them
#: again with ``--records``).
RECORDS = Path(tempfile.gettempdir()) / "pcmapq-corpus.jsonl"


# ---- running ---------------------------------------------------------------------------------

def pose_error(result, known: Similarity2D) -> tuple[float, float]:
    """How far the found pose puts the truth's centre from where the known one does (metres),
    and the difference of their headings (degrees)."""
    rows, cols = result.grid.shape
    centre = result.grid.pixels_to_xy(np.array([[(cols - 1) / 2, (rows - 1) / 2]]))
    found = result.transform
    where = found.apply(known.inverse().apply(centre))
    metres = float(np.linalg.norm(where - centre))
    degrees = abs((math.degrees(found.yaw - known.yaw) + 180.0) % 360.0 - 180.0)
    return metres, degrees


def measure(pair: Pair, folder: Path) -> Record:
    """Build one pair and score it."""
    record = Record(pair.name, pair.kind, pair.level, pair.same, pair.form)
    start = time.perf_counter()
    try:
        record.note = pair.note if isinstance(pair.note, str) else pair.note()
        record.displacement_m = (pair.displacement() if callable(pair.displacement) else
                                 pair.displacement)
        if pair.screen is not None:
            record.layouts = [layout.name for layout in pair.screen]
            screened = screen(*pair.screen, folder)
            record.best_fitness, record.shared_walls = screened.fitness, screened.shared
            if screened.dropped:
                record.dropped = True
                record.build_seconds = time.perf_counter() - start
                return record
        source, truth = pair.build_map(folder), pair.build_truth(folder)
        record.build_seconds = time.perf_counter() - start
        start = time.perf_counter()
        result = evaluate(source, truth, pair.settings)
        record.seconds = time.perf_counter() - start
    except Exception as err:  # a corpus run records what failed and goes on
        record.error = f"{type(err).__name__}: {err}"
        record.seconds = time.perf_counter() - start
        return record
    doc = result.to_dict(features=False)
    record.alignment = doc["alignment"]
    record.coverage = doc.get("coverage")
    record.consistency = doc.get("consistency")
    if pair.known is not None:
        record.pose_error_m, record.yaw_error_deg = pose_error(result, pair.known)
    return record


def run(pairs: Iterable[Pair], out: Path | None = None,
        progress: Callable[[Record], None] = lambda r: None) -> list[Record]:
    """Score every pair (maps built in a scratch folder, removed afterwards); with ``out``, write
    each record as one JSON line as soon as it is measured."""
    records = []
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="pcmapq_corpus_") as tmp, \
            (open(out, "w") if out is not None else _Null()) as sink:
        for pair in pairs:
            record = measure(pair, Path(tmp))
            records.append(record)
            sink.write(record.to_json() + "\n")
            sink.flush()
            progress(record)
    return records


class _Null:
    """A sink that keeps nothing."""

    def __enter__(self) -> _Null:
        return self

    def __exit__(self, *exc) -> None:
        return None

    def write(self, text: str) -> None:
        return None

    def flush(self) -> None:
        return None


# ---- markdown --------------------------------------------------------------------------------

def _level(level: float | str | None) -> str:
    return "-" if level is None else f"{level:g}" if isinstance(level, int | float) else level


def _spread(values: list[float], digits: int = 2) -> str:
    """'lo-hi' of some values ('-' when none)."""
    if not values:
        return "-"
    lo, hi = number(min(values), digits), number(max(values), digits)
    return lo if lo == hi else f"{lo}-{hi}"


def roc_table(records: list[Record], names: tuple[str, ...] = ("confidence",),
              steps: tuple[float, ...] = tuple(round(0.1 * i, 1) for i in range(11))) -> str:
    """Share of same-place and other-place pairs accepted per threshold, two columns per figure;
    then, per figure, the lowest threshold that accepts no other-place pair."""
    curves = {n: {p.threshold: p for p in roc(records, n, steps)} for n in names}
    lines = [header(["threshold"] + [f"{n}: {w}" for n in names for w in ("same", "other")])]
    for t in steps:
        lines.append(row([f"{t:.2f}"] + [cell for c in curves.values()
                                         for cell in (f"{100 * c[t].same:.0f} %",
                                                      f"{100 * c[t].other:.0f} %")]))
    for k, n in enumerate(names):
        s = safe(records, n)
        cells = ["-"] * (2 * len(names))
        if s is not None:
            cells[2 * k:2 * k + 2] = [f"{100 * s.same:.0f} %", f"{100 * s.other:.0f} %"]
        label = "none" if s is None else f"{s.threshold:.2f}"
        lines.append(row([f"{label} (lowest with no other place, {n})"] + cells))
    return "\n".join(lines)


def holdings_table(records: list[Record]) -> str:
    """What the corpus holds: per kind and level, the pairs, their forms and how far the
    degradation moves the walls."""
    lines = [header(["kind", "place", "level", "pairs", "forms", "walls moved, m"])]
    for g in verdict_groups(records):
        unit = KINDS.get(g.kind, "")
        lines.append(row([g.kind + (f" ({unit})" if unit else ""),
                          "same" if g.same else "other", _level(g.level), str(g.pairs),
                          ", ".join(g.forms), number(g.displacement, 2)]))
    return "\n".join(lines)


def verdicts_table(records: list[Record]) -> str:
    """Per kind and level: pairs, scored by the verdict, of them "same place, inconsistent
    map", accepted by the confidence alone, median confidence and median largest offset."""
    lines = [header(["kind", "level", "place", "pairs", "scored (verdict)",
                     "of them inconsistent", f"confidence >= {CURRENT}", "median confidence",
                     "median largest offset, m"])]
    for g in verdict_groups(records):
        wrong = g.scored < g.pairs if g.same else g.scored > 0
        cell = f"{g.scored} ({100 * g.share:.0f} %)"
        lines.append(row([g.kind, _level(g.level), "same" if g.same else "other", str(g.pairs),
                          f"**{cell}**" if wrong else cell, str(g.inconsistent),
                          str(g.accepted), number(g.confidence, 2), number(g.offset, 2)]))
    return "\n".join(lines)


def _size(name: str) -> str:
    """The group of an other layout by its name: its size ('30 x 12 m'), or 'round rooms'."""
    found = re.search(r"\d+ x \d+ m", name)
    return found.group(0) if found else name


def screening_table(records: list[Record]) -> str:
    """The screened synthetic other places per size of the other layout: layout pairs, best
    fitness and shared walls (ranges), pairs dropped."""
    groups: dict[str, list[Record]] = {}
    for r in records:
        if r.layouts:
            other = next((n for n in r.layouts if n == "round rooms" or " x " in n),
                         r.layouts[0])
            groups.setdefault(_size(other), []).append(r)
    lines = [header(["other layout", "layout pairs", "best fitness", "shared walls",
                     "pairs dropped"])]
    for size, group in groups.items():
        layouts = {tuple(r.layouts or ()): r for r in group}
        lines.append(row([size, str(len(layouts)),
                          _spread([r.best_fitness for r in layouts.values()
                                   if r.best_fitness is not None]),
                          _spread([r.shared_walls for r in layouts.values()
                                   if r.shared_walls is not None]),
                          f"{sum(r.dropped for r in group)} of {len(group)}"]))
    return "\n".join(lines)


def describe(r: Record) -> str:
    """'name (confidence c, distinctiveness d, recall r, fitness f)'."""
    a = r.alignment
    return (f"{r.name} (confidence {number(a.get('confidence'), 2)}, distinctiveness "
            f"{number(a.get('distinctiveness'), 2)}, truth recall "
            f"{number(a.get('truth_recall'), 2)}, fitness {number(a.get('fitness'), 2)})")


def largest_turn(r: Record) -> float | None:
    """How far the region of the largest offset turns, degrees (None without one)."""
    offset = value(r, "consistency.largest_offset_m")
    turns = [g.get("turn_deg") for g in (r.consistency or {}).get("regions", [])
             if offset is not None and g.get("held") and g.get("offset_m") == offset]
    return abs(float(turns[0])) if turns and isinstance(turns[0], int | float) else None


#: A largest offset whose region turns by more than this (degrees) fits walls elsewhere.
ELSEWHERE_DEG = 45.0


def wrong_line(r: Record) -> str:
    """'- name: verdict, confidence c, k of n parts agreeing, largest offset m (the turn of its
    region), shared walls'."""
    a = r.alignment
    cells = [f"\"{a.get('verdict', r.error or 'no verdict')}\"",
             f"confidence {number(a.get('confidence'), 2)}"]
    cells += [part] if (part := agreeing(r)) else []
    offset = value(r, "consistency.largest_offset_m")
    if offset is not None:
        turn = largest_turn(r)
        cells += [f"largest offset {number(offset, 2)} m" + (
            "" if turn is None else f" (its region turned {turn:.0f} degrees)")]
    cells += [] if r.shared_walls is None else [
        f"its layouts share {100 * r.shared_walls:.0f} % of their walls at their best pose"]
    return f"- {r.name}: " + ", ".join(cells)


KIND_TEXT = {
    "clean": "synthetic plans (`synth.building_plan` seeds 0-4, 24 x 16 m: outer walls, a "
             "corridor 2.2 m wide with rooms of random widths on both sides, an L-shaped wall, "
             "two pillars) in a map frame turned and shifted by a known transform, as a point "
             f"cloud (both faces of {THICKNESS} m walls, points {SPACING} m apart) and as an "
             f"image ({RESOLUTION} m per pixel), against the plan drawn as an image",
    "sample": "the shipped sample (`data/sample/scan.ply` against `truth.png`)",
    "real": "the real same-place maps of the section above (Intel and Freiburg 079 maps against "
            "their plans, four Halmstad maps against their layouts, Gazebo)",
    "noise": "plans 0-2 with every wall point moved by Gaussian noise of sigma (images: ragged "
             "walls drawn from such points, and a share sigma / (1 m) / 10 of the free cells "
             "marked occupied)",
    "missing walls": "plans 0-2 with that share of the inner walls dropped",
    "bend": "plans 0-2 bent about their lower-left corner (`synth.bend_segments`) so that the "
            "far corner moves by the level",
    "clutter": "plans 0-2 with that many boxes of 0.5 m added in the free space",
    "broken half": "plans 0-2 with the walls right of x = 12 m turned by the level about the "
                   "plan's middle (12, 8) m",
    "doubled half": "plans 0-2 with the walls right of x = 12 m drawn a second time, the level "
                    "higher (a map that drew a stretch twice); images: the hull of both drawn "
                    "free",
    "partial view": "plans 0-2 cut to the walls in that share of their width, from the left "
                    "(a map of part of the building), against the whole plan",
    "drift": f"the first {DRIFT_SCANS} scans of the CARMEN logs "
             f"{', '.join(DRIFT_LOGS)} placed along their poses re-integrated with a relative "
             "gain error of the level on every rotation and translation increment (seed 0), "
             "against the same scans at their corrected poses",
    "drift full log": "whole CARMEN logs re-integrated the same way, against the corrected log",
    "other carmen": "every CARMEN building's log against every other's",
    "other halmstad": "the Halmstad maps against the three other buildings' layouts",
    "other floor plans": "the Intel and Freiburg 079 maps against each other's plan",
    "other layout": "`synth.building_plan(seed, width, height)` of another outline (so the "
                    "corridor lies at another height) and another seed (so other rooms), as "
                    "points and images, against plans 0-4",
    "other rooms": "three round rooms (radii 5, 4 and 3 m) against plans 0-4",
    "other degraded": "the strongest level of each degradation of plans 0-2 (the maps of the "
                      "ladders) against two other layouts each",
}


def markdown(records: list[Record], names: tuple[str, ...] = ("confidence",),
             seconds: float | None = None) -> str:
    """The corpus's section: what it holds, the verdicts per kind and level, the real other
    places, the largest offsets, the ROC, the screening, the pairs that go wrong, wrong poses
    and failures. ``seconds``: the run's time (else the records' own)."""
    dropped = [r for r in records if r.dropped]
    screened = [r for r in records if r.layouts]
    everything = records
    records = kept(records)
    same = [r for r in records if r.same]
    other = [r for r in records if not r.same]
    if seconds is None:
        seconds = sum(r.seconds + r.build_seconds for r in everything)
    parts = PIECES[0] * PIECES[1]
    kinds = list(dict.fromkeys(r.kind for r in sorted(records, key=lambda r: _kind_key(r.kind))))
    lines = [
        "## Same place, inconsistent map, or another place: a labelled corpus", "",
        f"{len(records)} pairs of a map and a truth, each labelled with whether the map shows "
        f"the truth's place ({len(same)} do, {len(other)} show another place), scored with "
        "`force` and no detectors (`python -m bench.validation --only corpus`, or "
        "`python -m bench.validation.corpus`, which also analyses saved records again; "
        "`bench/validation/corpus.py` builds every pair, seeded). The verdict is the result's "
        f"`alignment.verdict`: \"{SAME}\" at confidence {CURRENT} or more; below it "
        f"\"{INCONSISTENT}\" when at least {MIN_AGREEING} of the map's {parts} parts, each "
        "placed on its own by the global search, land near the map's pose, or when its "
        f"pose's distinctiveness is at least {STANDS_OUT} with a truth recall above "
        f"{RECALL_NONE}; \"{LOW}\" for a map with free space (the images: their walls' "
        f"hull is free) that saw through less than {SEEN_THROUGH} of the truth's walls it "
        f"covers, with {ON_TRUTH} or more of its free space on the truth and a truth recall "
        f"above {RECALL_NONE}; else "
        f"\"{OTHER}\", refused unless forced. A pair is *scored* when its verdict is not "
        f"\"{OTHER}\". The whole corpus ran in {seconds:.0f} s.", "",
        "### What the corpus holds", "",
        holdings_table(records), "",
        "\"walls moved\" is how far the degradation moves the map's walls (median of the "
        "level's pairs): the noise's sigma along each axis; the largest move of a wall point "
        "for a bend or a broken half (the plan's far corner); the offset of a doubled half; 0 "
        "where walls are dropped, cut off or boxes added; for drift, the largest position "
        "error of the drifted trajectory.", "",
        *(f"- {kind}: {KIND_TEXT[kind]}." for kind in kinds if kind in KIND_TEXT),
    ]
    if screened:
        lines += [
            "", f"Plans of one size share much of their walls, so a synthetic other place "
            "is screened before it is scored: its two layouts, clean, are aligned by the same "
            "global search (the map's layout as points) and the pair is dropped when, at that "
            f"best pose, more than {100 * MAX_SHARED:.0f} % of either layout's wall points "
            f"(centre lines, {SHARED_STEP} m apart) lie within {SHARED_M} m of the other's "
            f"walls. {len(dropped)} of the {len(screened)} synthetic other-place pairs were "
            f"dropped; {len(screened) - len(dropped)} remain:", "",
            screening_table(everything)]
    lines += ["", "### Verdicts per kind and level", "",
              "Counts in bold are wrong: a same-place map refused, another place scored. "
              "\"median largest offset\": `consistency.largest_offset_m`, the largest offset "
              "that fits a held 4 m region of the map to the truth on its own, median over the "
              "level's scored maps.", "", verdicts_table(records), ""]
    real_other = [r for r in other if r.kind not in SYNTHETIC_OTHER]
    real_scored = [r for r in real_other if scored(r)]
    synth_other = [r for r in other if r.kind in SYNTHETIC_OTHER]
    lines += [f"Real other places scored: {len(real_scored)} of {len(real_other)}"
              + (":" if real_scored else "."), *(wrong_line(r) for r in real_scored)]
    if synth_other:
        lines += ["", f"Synthetic other places scored: "
                      f"{sum(scored(r) for r in synth_other)} of {len(synth_other)}."]
    growth = []
    for kind, unit in (("bend", "m of the far corner"), ("broken half", "degrees"),
                       ("doubled half", "m of offset"), ("drift", "% of drift")):
        levels = offsets(records, kind)
        if levels:
            values = [v for _, v in levels]
            growth.append(
                f"{kind}: {', '.join(number(v, 2) for v in values)} m at "
                f"{', '.join(_level(lv) for lv, _ in levels)} {unit} "
                f"({'grows' if rising(values) else 'does not grow'} with the level)")
    if growth:
        lines += ["", "Median largest offset per level, " + "; ".join(growth) + "."]
    elsewhere = [r for r in same if scored(r) and (largest_turn(r) or 0.0) > ELSEWHERE_DEG]
    if elsewhere:
        lines += ["", f"Same-place maps whose largest offset comes from a region turned by more "
                      f"than {ELSEWHERE_DEG:.0f} degrees (a region that fits walls elsewhere, "
                      "not one moved back into place): " + "; ".join(
                          f"{r.name}, {number(value(r, 'consistency.largest_offset_m'), 2)} m "
                          f"turned {largest_turn(r):.0f} degrees"
                          + ("" if r.displacement_m is None else
                             f" (walls moved up to {number(r.displacement_m, 2)} m)")
                          for r in elsewhere) + "."]
    lines += ["", "### ROC of the confidence: share accepted at each threshold", "",
              roc_table(records, names), ""]
    lines += [f"The verdict as the accept rule scores {100 * _share(same):.0f} % of the "
              f"same-place pairs ({sum(scored(r) for r in same)} of {len(same)}, "
              f"{sum(r.alignment.get('verdict') == INCONSISTENT for r in same)} of them as "
              f"\"{INCONSISTENT}\", {sum(r.alignment.get('verdict') == LOW for r in same)} as "
              f"\"{LOW}\") and {100 * _share(other):.0f} % of the other-place pairs "
              f"({sum(scored(r) for r in other)} of {len(other)}); the confidence alone at "
              f"{CURRENT} accepts {sum(accepted(r, CURRENT) for r in same)} and "
              f"{sum(accepted(r, CURRENT) for r in other)}."]
    s = safe(records)
    if s is not None:
        lines += ["", f"The lowest confidence threshold that accepts no other-place pair, "
                      f"{s.threshold:.2f}, accepts {100 * s.same:.0f} % of the same-place pairs "
                      f"({sum(accepted(r, s.threshold) for r in same)} of {len(same)})."]
    if other:
        top = max(other, key=lambda r: value(r, "confidence") or 0.0)
        lines += ["", f"Worst other-place pair: {describe(top)}."]
        searched = [r for r in other if value(r, "distinctiveness") is not None]
        if searched:
            most = max(searched, key=lambda r: value(r, "distinctiveness"))
            lines += ["", f"Most distinct other-place pose: {describe(most)}. "
                          f"{stand_out_rule()}"]
    refused = [r for r in same if not scored(r)]
    let_in = [r for r in other if scored(r)]
    lines += ["", "### Pairs that go wrong", "",
              f"Same place refused (\"{OTHER}\"): {len(refused)} of {len(same)}"
              + (":" if refused else "."), *(wrong_line(r) for r in refused), "",
              f"Another place scored: {len(let_in)} of {len(other)}"
              + (":" if let_in else "."), *(wrong_line(r) for r in let_in)]
    wrong = pose_wrong(records)
    known = [r for r in same if r.pose_error_m is not None]
    lines += ["", f"Poses off by more than 1 m or 5 degrees at the truth's centre: {len(wrong)} "
                  f"of the {len(known)} same-place pairs with a known pose (for a bent, broken or "
                  "drifted map the known pose is that of the map before it was distorted)"
                  + (":" if wrong else ".")]
    lines += [f"- {r.name}: {number(r.pose_error_m, 2)} m, {number(r.yaw_error_deg, 1)} deg, "
              f"confidence {number(value(r, 'confidence'), 2)}" for r in wrong]
    failed = [r for r in everything if r.error]
    if failed:
        lines += ["", "Failed runs:", *(f"- {r.name}: {r.error}" for r in failed)]
    return "\n".join(lines)


def _share(records: list[Record]) -> float:
    """The share of the records the verdict scores."""
    return sum(scored(r) for r in records) / len(records) if records else 0.0


def cases(data: Path) -> list[Case]:
    """None: the corpus keeps no stored references (its records are in :data:`RECORDS`)."""
    return []


def section(data: Path, record: Figures) -> Section:
    """The corpus measured (records written to :data:`RECORDS` as they come) and its section
    of docs/validation.md."""
    start = time.perf_counter()
    records = run(pairs(data), RECORDS)
    print(f"corpus: records in {RECORDS}", file=sys.stderr, flush=True)
    return Section(markdown(records, seconds=time.perf_counter() - start))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.validation.corpus",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" / "corpus.jsonl",
                        help="JSON lines written as the pairs are measured (default: %(default)s)")
    parser.add_argument("--data", type=Path, default=DATA,
                        help="the shared data folder (default: %(default)s)")
    parser.add_argument("--only", default=None,
                        help="only the pairs whose name contains this text")
    parser.add_argument("--fields", default="confidence",
                        help="figures of the ROC, comma-separated (default: %(default)s)")
    parser.add_argument("--records", type=Path, default=None,
                        help="analyse the records of this file instead of running the corpus")
    parser.add_argument("--list", action="store_true", help="list the pairs; run nothing")
    args = parser.parse_args(argv)
    chosen = [p for p in pairs(args.data) if args.only is None or args.only in p.name]
    if args.list:
        for p in chosen:
            print(f"{p.name}\t{p.kind}\t{_level(p.level)}\t{'same' if p.same else 'other'}")
        return 0
    if args.records is not None:
        records = load(args.records)
    else:
        if not args.data.is_dir():
            print(f"{args.data}: absent: synthetic pairs only", file=sys.stderr)

        def say(r: Record) -> None:
            what = (f"dropped (shares {number(r.shared_walls, 2)} of its walls)" if r.dropped
                    else f"confidence {number(value(r, 'confidence'), 2)}, "
                         f"{r.alignment.get('verdict')}")
            print(f"{r.name}: {what}, {r.build_seconds + r.seconds:.1f} s"
                  + (f" ({r.error})" if r.error else ""), file=sys.stderr, flush=True)

        start = time.perf_counter()
        records = run(chosen, args.out, say)
        print(f"{len(records)} pairs in {time.perf_counter() - start:.0f} s; records in "
              f"{args.out}", file=sys.stderr)
    print(markdown(records, tuple(args.fields.split(","))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
