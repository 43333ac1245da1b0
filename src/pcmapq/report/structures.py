"""The 3D structures of a result (:mod:`pcmapq.match.structures`) in the terminal table and
the HTML report, beside the 2D detectors: their scores and counts, the sizes of their
displacements, and the planes missing, extra or displaced."""

from __future__ import annotations

import html

import numpy as np

from pcmapq.core.stats import Stats
from pcmapq.match.structures import NOUNS, Structures3D
from pcmapq.report.text import number, score
from pcmapq.results.result import Result


def structure_scores(result: Result) -> dict[str, tuple[str, ...]]:
    """Each structure detector's row of the score table (the 2D detectors' columns:
    quality, precision, f1, truth structures, matched truth, map structures, matched map);
    none without structures."""
    if result.structures is None:
        return {}
    rows = {}
    for name, found in result.structures.detectors.items():
        m = found.matching
        rows[name] = (score(m.quality), score(m.precision), score(m.f1),
                      str(m.truth_structures), str(m.matched), str(m.map_structures),
                      str(m.matched))
    return rows


def displacement_stats(result: Result) -> dict[str, Stats]:
    """Each structure detector's statistics of its displacements' sizes, metres."""
    if result.structures is None:
        return {}
    return {name: Stats.of(np.abs(found.matching.displacement))
            for name, found in result.structures.detectors.items()}


def thresholds(result: Result) -> str:
    """How the structures were matched, in words ('' without structures): the thresholds,
    the shortest line counted (when the settings record it) and the planes' own fit."""
    s = result.structures
    if s is None:
        return ""
    length = ((result.settings or {}).get("structures") or {}).get("line_length")
    lines = "" if length is None else f", lines from {length:g} m long"
    return (f"3D planes and plane lines within {s.max_angle:g} deg and {s.max_offset:g} m"
            f"{lines} (a plane's displacement along the truth plane's normal, signed)"
            f"{fit_words(s)}")


def fit_words(s: Structures3D) -> str:
    """The planes' own fit in words, as a clause ('' for a result without it)."""
    f = s.fit
    if f is None:
        return ""
    if f.applied:
        return (f", after the planes' own fit of {f.offset:.3f} m and {f.angle:.2f} deg "
                f"on {f.held} of {f.pairs} matched planes")
    return (f"; the planes' own fit ({f.offset:.3f} m, {f.angle:.2f} deg) not applied: it "
            f"would move a plane {f.largest_move:.2f} m, beyond the registration's "
            f"{f.reach:g} m")


def notes(result: Result) -> list[str]:
    """One line per structure detector with an undefined score: ``name: n/a: why``."""
    if result.structures is None:
        return []
    return [f"{name}: n/a: {note}" for name, found in result.structures.detectors.items()
            if (note := found.matching.note(NOUNS[name])) is not None]


def html_rows(result: Result, stats_cells) -> list[list[str]]:
    """The structure detectors' rows of the HTML score table (its columns: detector, quality,
    precision, f1, truth, map, matched truth, matched map, then ``stats_cells(stats)``)."""
    rows = []
    for name, cells in structure_scores(result).items():
        q, p, f1, truth, matched, map_, matched_map = cells
        rows.append([f"{name} (3D)", q, p, f1, truth, map_, matched, matched_map,
                     *stats_cells(displacement_stats(result)[name])])
    return rows


def planes_html(result: Result) -> str:
    """Every plane of the truth and the map: the matched ones, the largest displacement first,
    then the truth's missing ones and the map's extra ones, as a table; '' without
    structures."""
    if result.structures is None:
        return ""
    found = result.structures.detectors["planes"]
    m, t, p = found.matching, found.truth, found.map
    order = np.argsort(-np.abs(m.displacement), kind="stable")
    rows = [["matched", _xyz(t.centroid[m.truth_idx[k]]), _xyz(t.normal[m.truth_idx[k]]),
             number(t.area[m.truth_idx[k]], 1), number(m.displacement[k]),
             number(m.angle[k], 2)] for k in order]
    rows += [["missing", _xyz(t.centroid[i]), _xyz(t.normal[i]), number(t.area[i], 1), "-",
              "-"] for i in m.missing]
    rows += [["extra", _xyz(p.centroid[j]), _xyz(p.normal[j]), number(p.area[j], 1), "-",
              "-"] for j in m.extra]
    head = ["plane", "centroid [m]", "normal", "area [m²]", "displacement [m]", "angle [deg]"]
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
                   for row in rows)
    table = "<table><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in head) + \
        f"</tr>{body}</table>"
    return (f"<h3>3D planes: {len(m.missing)} missing, {len(m.extra)} extra, {m.matched} "
            f'matched (the largest displacement first)</h3><div class="list">{table}</div>')


def _xyz(v: np.ndarray) -> str:
    return ", ".join(f"{x:.2f}" for x in v)
