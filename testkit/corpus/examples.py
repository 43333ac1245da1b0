"""Hand-made corpus records with known answers, for the tests of the corpus's analysis and of its
section of docs/validation.md."""

from __future__ import annotations

from pcmapq.results.result import INCONSISTENT, OTHER, SAME

from .records import Record


def record(name: str, same: bool, confidence: float | None, kind: str = "k",
           level: float | None = 1.0, **alignment: float) -> Record:
    """A scored pair: its labels and its alignment block (the confidence and ``alignment``);
    no block for a run that failed (``confidence`` None)."""
    block = {} if confidence is None else {"confidence": confidence, **alignment}
    return Record(name, kind, level, same, "points", alignment=block)


#: 3 same-place pairs (0.9, 0.6, 0.3) and 3 other-place pairs (0.0, 0.2, 0.55).
RECORDS = [record("s1", True, 0.9, truth_recall=0.2), record("s2", True, 0.6, truth_recall=0.5),
           record("s3", True, 0.3, truth_recall=0.9),
           record("o1", False, 0.0, "o", truth_recall=0.1),
           record("o2", False, 0.2, "o", truth_recall=0.3),
           record("o3", False, 0.55, "o", truth_recall=0.4)]


def verdict(name: str, same: bool, kind: str, level: float | str | None, confidence: float,
            said: str, agrees: int = 0, offset: float | None = None,
            dropped: bool = False) -> Record:
    """A pair with its verdict (``said``), ``agrees`` of 8 parts agreeing when the verdict was
    not the confidence's alone, the largest offset of its consistency map; a dropped one
    shares half its walls (the screening)."""
    parts = [{"agrees": k < agrees} for k in range(8)] if said != SAME else []
    return Record(name, kind, level, same, "points",
                  alignment={"confidence": confidence, "verdict": said, "parts": parts},
                  consistency={"largest_offset_m": offset}, dropped=dropped,
                  shared_walls=0.5 if dropped else None,
                  layouts=["plan 0", "plan 10 30 x 12 m"] if dropped else None)


#: A bend ladder (offsets growing), a same-place map refused, a real other place refused, a
#: synthetic other place scored as inconsistent, and one dropped by the screening.
VERDICTS = [
    verdict("bend a 0.2", True, "bend", 0.2, 1.0, SAME, offset=0.1),
    verdict("bend b 0.2", True, "bend", 0.2, 0.9, SAME, offset=0.2),
    verdict("bend a 1", True, "bend", 1.0, 0.3, INCONSISTENT, 3, offset=0.8),
    verdict("bend b 1", True, "bend", 1.0, 0.1, OTHER, 1),
    verdict("carmen x vs y", False, "other carmen", None, 0.0, OTHER, 0),
    verdict("layout p vs q", False, "other layout", "30 x 12 m", 0.2, INCONSISTENT, 2,
            offset=0.5),
    verdict("layout r vs s", False, "other layout", "30 x 12 m", 0.9, SAME,
            dropped=True),
]
