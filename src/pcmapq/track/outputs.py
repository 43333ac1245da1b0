"""A tracked run's files (:func:`write_track`): ``track.csv`` (one row per step),
``track.json`` (every step, the worst drop, the settings), ``track.png`` and ``track.html``
(:mod:`pcmapq.report.timeline`). Metres, degrees and seconds; an undefined figure is an empty
cell and ``null``."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

from pcmapq import __version__
from pcmapq.core.words import count, plural
from pcmapq.io.writers import OutputSet, write_atomic
from pcmapq.results.result import DECIMALS, rounded
from pcmapq.track.drop import Drop
from pcmapq.track.timeline import Step

if TYPE_CHECKING:  # tracked.py builds its rows with step_rows
    from pcmapq.track.tracked import Tracked

#: The files a tracked run writes into its folder.
FILES = ("track.csv", "track.json", "track.png", "track.html")
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


def inputs_of(tracked: Tracked) -> dict[str, str]:
    """What a tracked run scored, in words, by name: the run, its poses, the truth, the
    reference poses and how they compare, the step rule (``tracked.every``)."""
    run, options, every = tracked.run, tracked.pose_options, tracked.every
    words = {"run": str(run.path), "poses": run.poses_source,
             "truth": str(tracked.truth.source.path)}
    if tracked.reference is not None:
        how = {(True, True): "aligned with scale (Sim(3) Umeyama)",
               (True, False): "aligned (SE(3) Umeyama)",
               (False, True): "scale corrected, not aligned",
               (False, False): "not aligned"}[options.align, options.correct_scale]
        words["reference poses"] = (f"{tracked.reference}; {how}, RPE over {options.delta} "
                                    f"{plural(options.delta, 'scan')}")
    words["steps"] = (f"every {count(every['every_scans'], 'scan')}" if every.get("every_scans")
                      else f"every {every['every_m']:g} m travelled" if every.get("every_m")
                      else f"every map published, at most one per {every['every_s']:g} s"
                      if every.get("every_s") else "every map published") + ", and the last"
    return words


def write_track(tracked: Tracked, out: Path, command: str | None) -> list[Path]:
    """Write the run's files (:data:`FILES`) into ``out`` (made if missing), all or none; the
    paths."""
    from pcmapq.report.plot import png_bytes
    from pcmapq.report.timeline import timeline_figure, timeline_html

    rows = tracked.rows
    drop = None if tracked.drop is None else asdict(tracked.drop)
    inputs = inputs_of(tracked)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / name for name in FILES]
    with OutputSet() as outputs:
        write_atomic(paths[0], track_csv(rows), outputs)
        write_atomic(paths[1], track_json(
            rows, tracked.drop, run=tracked.run.path, poses=tracked.run.poses_source,
            truth=tracked.truth.source.path, reference=tracked.reference,
            pose_options=asdict(tracked.pose_options), settings=tracked.settings.to_dict(),
            every=tracked.every, command=command), outputs)
        title = f"{tracked.run.path.name} against {tracked.truth.source.path.name}"
        curves = png_bytes(timeline_figure(rows, drop, title))
        write_atomic(paths[2], curves, outputs)
        write_atomic(paths[3], timeline_html(rows, drop, tracked.shown, tracked.result,
                                             tracked.path_xy, inputs=inputs, command=command,
                                             asked=tracked.asked, curves=curves), outputs)
        outputs.commit()
    return paths
