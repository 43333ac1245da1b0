"""What a corpus run records of each pair (:class:`Record`), and how well a figure of the result
(the confidence by default) tells the two labels apart: ROC, acceptance per kind and level, the
verdicts."""

from __future__ import annotations

import json
import math
import statistics
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path

from pcmapq.results.result import INCONSISTENT, LOW, SAME

from .pairs import CURRENT, KINDS


@dataclass
class Record:
    """One pair's result: its labels, the whole "alignment" block of ``Result.to_dict()``
    (fitness, truth recall, agreement, distinctiveness, confidence, a verdict where there is
    one), the coverage, the "consistency" block where there is one, the pose error against
    the known transform at the truth's centre (metres, degrees; None where unknown), seconds
    to build the map and truth (and screen them) and to evaluate, the error if the run failed,
    what the level means, how far the degradation moves the walls (metres); for a screened
    pair, its layouts' names, their best fitness and shared walls (:func:`screen`), and
    whether it was dropped (then nothing was scored)."""

    name: str
    kind: str
    level: float | str | None
    same: bool
    form: str
    alignment: dict = field(default_factory=dict)
    coverage: float | None = None
    consistency: dict | None = None
    pose_error_m: float | None = None
    yaw_error_deg: float | None = None
    build_seconds: float = 0.0
    seconds: float = 0.0
    error: str | None = None
    note: str = ""
    displacement_m: float | None = None
    layouts: list[str] | None = None
    best_fitness: float | None = None
    shared_walls: float | None = None
    dropped: bool = False

    def summary(self) -> dict:
        """The figures a stored reference would keep."""
        return {"alignment": self.alignment, "coverage": self.coverage,
                "consistency": self.consistency}

    def to_json(self) -> str:
        return json.dumps(asdict(self), sort_keys=True)

    @classmethod
    def from_dict(cls, doc: dict) -> Record:
        return cls(**doc)


def load(path: Path) -> list[Record]:
    """Records saved by :func:`run`."""
    return [Record.from_dict(json.loads(line)) for line in path.read_text().splitlines()
            if line.strip()]


def value(record: Record, name: str) -> float | None:
    """A numeric figure of a record by name: a key of its alignment block, one of its fields
    (coverage, pose_error_m, ...), or a dotted path ('consistency.largest_offset_m'). None when
    absent or not a number (a failed run has none)."""
    if "." in name:
        head, *rest = name.split(".")
        got = getattr(record, head, None)
        for key in rest:
            got = got.get(key) if isinstance(got, dict) else None
    elif name in record.alignment:
        got = record.alignment[name]
    else:
        got = getattr(record, name, None)
    if isinstance(got, bool) or not isinstance(got, int | float) or math.isnan(got):
        return None
    return float(got)


def accepted(record: Record, threshold: float, name: str = "confidence") -> bool:
    """Whether the figure reaches ``threshold`` (a missing figure is refused)."""
    v = value(record, name)
    return v is not None and v >= threshold


#: Thresholds of the ROC: 0 to 1 in steps of 0.01.
THRESHOLDS = tuple(round(0.01 * i, 2) for i in range(101))


@dataclass(frozen=True)
class Point:
    """One threshold of the ROC: shares of same-place and other-place pairs accepted."""

    threshold: float
    same: float
    other: float


def roc(records: list[Record], name: str = "confidence",
        thresholds: Iterable[float] = THRESHOLDS) -> list[Point]:
    """For each threshold, the share of same-place and of other-place pairs whose figure
    ``name`` reaches it."""
    same = [r for r in records if r.same]
    other = [r for r in records if not r.same]

    def share(group: list[Record], t: float) -> float:
        return sum(accepted(r, t, name) for r in group) / len(group) if group else 0.0

    return [Point(t, share(same, t), share(other, t)) for t in thresholds]


def safe(records: list[Record], name: str = "confidence",
         thresholds: Iterable[float] = THRESHOLDS) -> Point | None:
    """The lowest threshold that accepts no other-place pair, with the shares it accepts (None
    when every threshold accepts one)."""
    return next((p for p in roc(records, name, thresholds) if p.other == 0.0), None)


@dataclass(frozen=True)
class Group:
    """The pairs of one kind, form and level: how many, how many reach the threshold, and the
    figure's median, smallest and largest values (None when no pair has it)."""

    kind: str
    form: str
    level: float | str | None
    same: bool
    pairs: int
    accepted: int
    median: float | None
    low: float | None
    high: float | None

    @property
    def share(self) -> float:
        return self.accepted / self.pairs if self.pairs else 0.0


def _order(level: float | str | None) -> tuple:
    return (0, 0.0, "") if level is None else (
        (1, float(level), "") if isinstance(level, int | float) else (2, 0.0, str(level)))


def acceptance(records: list[Record], threshold: float = CURRENT,
               name: str = "confidence") -> list[Group]:
    """Per kind, form and level (in KINDS' order, then form, then level): the pairs accepted
    at ``threshold`` and the figure's median and range."""
    groups: dict[tuple, list[Record]] = {}
    for r in records:
        groups.setdefault((r.kind, r.form, r.level), []).append(r)
    kinds = list(KINDS)

    def key(k: tuple) -> tuple:
        return (kinds.index(k[0]) if k[0] in kinds else len(kinds), k[0], k[1], _order(k[2]))

    out = []
    for k in sorted(groups, key=key):
        group = groups[k]
        values = [v for r in group if (v := value(r, name)) is not None]
        out.append(Group(k[0], k[1], k[2], group[0].same, len(group),
                         sum(accepted(r, threshold, name) for r in group),
                         statistics.median(values) if values else None,
                         min(values) if values else None, max(values) if values else None))
    return out


def pose_wrong(records: list[Record], metres: float = 1.0, degrees: float = 5.0) -> list[Record]:
    """Same-place pairs with a known pose whose found pose is off by more than ``metres`` or
    ``degrees``."""
    return [r for r in records if r.same and r.pose_error_m is not None
            and (r.pose_error_m > metres or (r.yaw_error_deg or 0.0) > degrees)]


def kept(records: list[Record]) -> list[Record]:
    """The records scored: without the synthetic other places dropped by the screening."""
    return [r for r in records if not r.dropped]


def scored(record: Record) -> bool:
    """Scored by the verdict: "same place", "same place, inconsistent map" or "same place, low
    confidence" (a failed run or a result without a verdict is not)."""
    return record.alignment.get("verdict") in (SAME, INCONSISTENT, LOW)


def agreeing(record: Record) -> str:
    """'k of n parts agreeing', or '' when no part was placed (the confidence settled it)."""
    parts = record.alignment.get("parts") or []
    return f"{sum(bool(p.get('agrees')) for p in parts)} of {len(parts)} parts agreeing" if (
        parts) else ""


@dataclass(frozen=True)
class Verdicts:
    """The pairs of one kind and level: how many, the forms, how many the verdict scores and
    how many of those as "same place, inconsistent map", how many the confidence alone
    accepts, the median confidence, the median largest offset of the consistency map (over
    the maps that have one) and the median displacement of the degradation (None when
    absent)."""

    kind: str
    level: float | str | None
    same: bool
    pairs: int
    forms: tuple[str, ...]
    scored: int
    inconsistent: int
    accepted: int
    confidence: float | None
    offset: float | None
    displacement: float | None

    @property
    def share(self) -> float:
        return self.scored / self.pairs if self.pairs else 0.0


def _median(values: Iterable[float | None]) -> float | None:
    got = [v for v in values if v is not None]
    return statistics.median(got) if got else None


def _kind_key(kind: str) -> tuple[int, str]:
    kinds = list(KINDS)
    return (kinds.index(kind) if kind in kinds else len(kinds), kind)


def verdict_groups(records: list[Record]) -> list[Verdicts]:
    """Per kind and level (forms together; KINDS' order, then level): the verdicts."""
    groups: dict[tuple, list[Record]] = {}
    for r in records:
        groups.setdefault((r.kind, r.level), []).append(r)
    out = []
    for (kind, level), group in sorted(groups.items(),
                                       key=lambda kv: (_kind_key(kv[0][0]), _order(kv[0][1]))):
        out.append(Verdicts(
            kind, level, group[0].same, len(group),
            tuple(dict.fromkeys(r.form for r in group)), sum(scored(r) for r in group),
            sum(r.alignment.get("verdict") == INCONSISTENT for r in group),
            sum(accepted(r, CURRENT) for r in group),
            _median(value(r, "confidence") for r in group),
            _median(value(r, "consistency.largest_offset_m") for r in group),
            _median(r.displacement_m for r in group)))
    return out


def offsets(records: list[Record], kind: str) -> list[tuple[float | str | None, float | None]]:
    """Per level of a ladder: the median largest offset of its maps' consistency maps, m."""
    return [(g.level, g.offset) for g in verdict_groups(records) if g.kind == kind]


def rising(values: list[float | None]) -> bool:
    """Whether the values grow from each level to the next (none missing)."""
    got = [v for v in values if v is not None]
    return len(got) == len(values) and all(b > a for a, b in zip(got, got[1:], strict=False))
