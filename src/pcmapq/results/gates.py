"""Pass/fail gates on a result's figures, for CI: ``--fail-under KEY=VALUE,...`` fails a figure
below its bound (qualities, precisions, coverage), ``--fail-over KEY=VALUE,...`` one above it
(distances, metres). Plain functions over the result's JSON document
(:meth:`pcmapq.results.result.Result.to_dict`), so that every row of a batch is judged alike.

A key is a short name (``harris.quality``, ``accuracy.mean``, ``f_score@0.1``, ``coverage``,
``alignment.confidence``; :func:`short_names`) or any dotted path of the JSON
(``detectors.sift.displacement_m.p95``, ``distances.f_score.0.f``). A figure that is null
(nothing to measure) fails its gate. A bound equal to the figure passes."""

from __future__ import annotations

import difflib
import json
import math
import re
from dataclasses import dataclass
from typing import Any

from pcmapq.core.errors import InputError
from pcmapq.core.words import count
from pcmapq.results import figures

#: The exit code of a run whose figures fail a gate (0 scored, 1 evaluation failed, 2 usage).
EXIT_CODE = 3
#: The two directions and the option of each.
UNDER, OVER = "under", "over"
OPTIONS = {UNDER: "--fail-under", OVER: "--fail-over"}
#: The top-level keys of the result's JSON (``alignment_3d``, ``distances_3d``,
#: ``consistency_3d``: two 3D clouds registered; ``map_3d``: two 3D clouds in one frame;
#: ``structures_3d``: two 3D clouds; ``rooms``: the rooms detector ran).
TOP_LEVEL = ("pcmapq", "settings", "map", "truth", "alignment", "consistency", "frames",
             "coverage", "footprint", "scored_against", "distances", "noref", "detectors",
             "matches", "missing", "extra", "alignment_3d", "distances_3d", "map_3d",
             "consistency_3d", "structures_3d", "rooms")
_F_SCORE = re.compile(r"^(f_score|wall_precision)(_3d)?(?:@(.*))?$")


class GateError(InputError):
    """A gate that cannot be read or resolved: a usage error, exit 2, one line."""


@dataclass(frozen=True)
class Gate:
    """``key`` (as typed) must not be under (``direction`` "under") or over ("over")
    ``bound``, in the figure's unit (metres for distances)."""

    key: str
    bound: float
    direction: str

    @property
    def option(self) -> str:
        """The command-line option that sets this gate, ``--fail-under`` or ``--fail-over``."""
        return OPTIONS[self.direction]

    def passes(self, value: float | None) -> bool:
        """Whether ``value`` is within the bound; None (nothing to measure) never is."""
        if value is None:
            return False
        return value >= self.bound if self.direction == UNDER else value <= self.bound


@dataclass(frozen=True)
class Outcome:
    """A gate judged on one result: the JSON ``path`` its key names, the figure there (None:
    nothing to measure, with the result's ``note`` on why when it has one), and the verdict."""

    gate: Gate
    path: str
    value: float | None
    passed: bool
    note: str | None = None

    def line(self) -> str:
        """One line naming the figure, its value and the bound: ``harris.quality = 0.75,
        under the bound 0.8 (--fail-under)``."""
        g, unit = self.gate, _unit(self.path)
        if self.value is None:
            why = f": {self.note}" if self.note else ""
            return (f"{g.key} is n/a (nothing to measure{why}), so it fails its bound "
                    f"{g.bound}{unit} ({g.option})")
        return f"{g.key} = {self.value}{unit}, {g.direction} the bound {g.bound}{unit} ({g.option})"

    def to_dict(self) -> dict[str, Any]:
        """The JSON's record of this gate."""
        return {"key": self.gate.key, "path": self.path, "option": self.gate.option,
                "bound": self.gate.bound, "value": self.value, "passed": self.passed}


def parse_gates(text: str | None, direction: str) -> list[Gate]:
    """``KEY=VALUE,KEY=VALUE,...`` (``direction`` "under" or "over") as gates; None: none.
    Each key's form is checked (a short name, or a dotted path that starts at one of the JSON's
    top-level keys); whether a dotted path exists is known only from a result (:func:`check`).
    A bad pair, key or bound: :class:`GateError`."""
    if text is None:
        return []
    option = OPTIONS[direction]
    gates = []
    for pair in text.split(","):
        key, sep, value = (part.strip() for part in pair.partition("="))
        if not sep or not key:
            raise GateError(f"{option}: expected KEY=VALUE pairs separated by commas, got "
                            f"{pair.strip()!r} (e.g. {option} harris.quality=0.8)")
        try:
            bound = float(value)
        except ValueError:
            bound = math.nan
        if not math.isfinite(bound):
            raise GateError(f"{option} {key}: the bound must be a finite number, got {value!r}")
        _check_key(key, option)
        gates.append(Gate(key, bound, direction))
    return gates


def parse_rules(under: str | None, over: str | None) -> list[Gate]:
    """The gates of ``--fail-under`` and ``--fail-over``, in that order."""
    return parse_gates(under, UNDER) + parse_gates(over, OVER)


def short_names() -> list[str]:
    """Every short key: each named figure (:data:`~pcmapq.results.figures.FIGURES`), the
    aliases, and the F-score forms (``f_score@TAU`` stands for any tau)."""
    return [f.name for f in figures.FIGURES if f.number] + list(figures.ALIASES) + [
        form for name in figures.TAU_FIELDS for form in (name, f"{name}@TAU", f"{name}_3d@TAU")]


def json_path(key: str, doc: dict) -> tuple[str | int, ...]:
    """The JSON path a key names in ``doc``: a figure's name (or alias) its figure's path, a
    dotted path split (digits index lists). ``f_score@TAU`` names the F-score at tau metres;
    ``f_score`` alone, the only one (an error when the result has several)."""
    if (m := _F_SCORE.match(key)) is not None:
        block = "distances_3d" if m[2] else "distances"
        field = figures.TAU_FIELDS[m[1]]
        return (block, "f_score", _tau_index(key, m[3], doc.get(block)), field)
    name = figures.ALIASES.get(key, key)
    if (figure := figures.by_name().get(name)) is not None:
        return figure.path
    return tuple(int(s) if s.isdigit() else s for s in key.split("."))


def check(gates: list[Gate], doc: dict) -> list[Outcome]:
    """Each gate judged on the result's JSON ``doc``. A key the result does not have, or that
    names no number (a text, a group): :class:`GateError`."""
    outcomes = []
    for gate in gates:
        try:
            path = json_path(gate.key, doc)
        except GateError as error:
            raise GateError(f"{gate.option} {error}") from None
        value, parent = _lookup(gate, path, doc)
        note = parent.get("note") if isinstance(parent, dict) and value is None else None
        outcomes.append(Outcome(gate, ".".join(map(str, path)), value, gate.passes(value),
                                note if isinstance(note, str) else None))
    return outcomes


def failures(gates: list[Gate], doc: dict) -> list[str]:
    """One line per gate the result's JSON ``doc`` fails (none: all pass)."""
    return [o.line() for o in check(gates, doc) if not o.passed]


def with_gates(doc: dict, outcomes: list[Outcome]) -> dict:
    """The JSON document with a ``gates`` block: every gate, its figure and whether it passed."""
    return {**doc, "gates": [o.to_dict() for o in outcomes]}


def to_json(doc: dict) -> str:
    """A JSON document as :meth:`~pcmapq.results.result.Result.to_json` writes one (strict,
    indented)."""
    return json.dumps(doc, indent=2, allow_nan=False) + "\n"


def _check_key(key: str, option: str) -> None:
    """Refuse a key that is neither a short name nor a dotted path from a top-level key."""
    if (m := _F_SCORE.match(key)) is not None:
        if m[3] is not None and _tau(m[3]) is None:
            raise GateError(f"{option} {key}: expected {m[1]}@TAU with TAU in metres, e.g. "
                            f"{m[1]}@0.1")
        return
    if "" not in key.split(".") and json_path(key, {})[0] in TOP_LEVEL:
        return
    close = difflib.get_close_matches(key, short_names(), n=3, cutoff=0.6)
    hint = f"did you mean {' or '.join(close)}? " if close else ""
    raise GateError(f"{option}: unknown key {key!r}; {hint}keys: harris.quality, sift.f1, "
                    "hough.precision, accuracy.mean, completeness.median, chamfer, "
                    "f_score@0.1, coverage, alignment.confidence, or a dotted path of the "
                    "--json result (e.g. detectors.sift.displacement_m.p95)")


def _tau(text: str) -> float | None:
    """A tau in metres (positive, finite), or None."""
    try:
        tau = float(text)
    except ValueError:
        return None
    return tau if 0 < tau < math.inf else None


def _tau_index(key: str, text: str | None, block: dict | None) -> int:
    """The index in ``block``'s ``f_score`` list of the F-score ``key`` names."""
    if block is None:
        raise GateError(f"{key}: the result has no 3D distances (two 3D clouds only)")
    scores = block.get("f_score") or []
    taus = [s["tau_m"] for s in scores]
    name = key.split("@")[0]
    listed = ", ".join(f"{name}@{t:g}" for t in taus) or "none"
    if text is None:
        if len(taus) == 1:
            return 0
        raise GateError(f"{key}: this result has an F-score at each of "
                        f"{count(len(taus), 'tau')}; name "
                        f"one: {listed}")
    tau = _tau(text)
    hit = [i for i, t in enumerate(taus) if tau is not None and math.isclose(t, tau,
                                                                           abs_tol=1e-9)]
    if not hit:
        raise GateError(f"{key}: no F-score at that tau in this result (it has: {listed}; "
                        "--tau sets them)")
    return hit[0]


def _lookup(gate: Gate, path: tuple[str | int, ...], doc: dict) -> tuple[float | None, Any]:
    """The number at ``path`` in ``doc`` and the group holding it; a missing step or a value
    that is not a number (nor null): :class:`GateError`."""
    node: Any = doc
    parent: Any = None
    for depth, step in enumerate(path):
        where = ".".join(map(str, path[:depth])) or "the top level"
        if isinstance(node, dict) and step in node:
            parent, node = node, node[step]
        elif isinstance(node, list) and isinstance(step, int) and step < len(node):
            parent, node = node, node[step]
        else:
            has = ", ".join(map(str, node)) if isinstance(node, dict) else \
                f"items 0 to {len(node) - 1}" if isinstance(node, list) and node else "nothing"
            raise GateError(f"{gate.option} {gate.key}: the result has no {step!r} in {where} "
                            f"(it has: {has})")
    if node is None:
        return None, parent
    if isinstance(node, bool) or not isinstance(node, int | float):
        kind = "a group" if isinstance(node, dict | list) else f"{node!r}"
        raise GateError(f"{gate.option} {gate.key}: {'.'.join(map(str, path))} is {kind}, "
                        "not a number")
    return node, parent


def _unit(path: str) -> str:
    """`` m`` after a distance, `` deg`` after an angle, nothing after a count or a share."""
    steps = path.split(".")
    if steps[-1] == "count":
        return ""
    if steps[-1].endswith("_deg"):
        return " deg"
    return " m" if any(s.endswith("_m") for s in steps) else ""
