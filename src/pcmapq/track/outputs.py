"""A tracked run's files: ``track.csv`` (one row per step), ``track.json`` (every step, the
worst drop, the settings), ``track.png`` and ``track.html`` (:mod:`pcmapq.report.timeline`).
Metres, degrees and seconds; an undefined figure is an empty cell and ``null``."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

from pcmapq import __version__
from pcmapq.results.result import DECIMALS, rounded
from pcmapq.track.drop import Drop
from pcmapq.track.timeline import Step

#: The columns every step has, before its figures.
HEAD = ("step", "scans", "time_s", "distance_m", "scored")


def step_rows(steps: list[Step]) -> list[dict[str, object]]:
    """One flat row per step: :data:`HEAD`, every figure any step has (None where this one
    has none), then the note."""
    names: dict[str, None] = {}
    for s in steps:
        names.update(dict.fromkeys(s.figures))
    return [{"step": s.step, "scans": s.scans, "time_s": s.time_s, "distance_m": s.distance_m,
             "scored": s.scored, **{n: s.figures.get(n) for n in names}, "note": s.note}
            for s in steps]


def _cell(value: object) -> str:
    """A CSV cell: empty for None, DECIMALS decimals for a float, 1/0 for a flag."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, float):
        return f"{value + 0.0:.{DECIMALS}f}"
    text = str(value)
    return '"' + text.replace('"', '""') + '"' if any(c in text for c in ',"\n') else text


def track_csv(rows: list[dict[str, object]]) -> str:
    """The rows as CSV, header first."""
    if not rows:
        return ""
    lines = [",".join(rows[0])] + [",".join(_cell(v) for v in r.values()) for r in rows]
    return "\n".join(lines) + "\n"




def track_json(rows: list[dict[str, object]], drop: Drop | None, *, run: Path, poses: str,
               truth: Path, reference: Path | None, pose_options: dict, settings: dict,
               every: dict, command: str | None) -> str:
    """The JSON document of a tracked run: its inputs (``poses``: the file of the run's poses
    or where they come from, in words; ``reference_poses`` and how they were compared, null
    without), step rule, settings, the worst drop and every step (floats rounded to
    DECIMALS)."""
    doc = {"pcmapq": {"version": __version__, "command": command},
           "run": str(run), "poses": poses, "truth": str(truth),
           "reference_poses": None if reference is None else str(reference),
           "pose_errors": None if reference is None else pose_options, "every": every,
           "worst_drop": None if drop is None else asdict(drop),
           "settings": settings, "steps": rows}
    return json.dumps(rounded(doc), indent=2, allow_nan=False) + "\n"
