"""How a figure reads wherever it is shown: a number, `n/a` for an undefined score, `-` for
nothing measured; the one-line verdict on a Result; lines wrapped between whole values."""

from __future__ import annotations

import re
from collections.abc import Sequence

from pcmapq.core.words import count
from pcmapq.match.structures import NOUNS
from pcmapq.metrics.map_gaussians import MapGaussians
from pcmapq.results.result import INCONSISTENT, LOW, OTHER, Result

#: What the terms of the table mean, in one short paragraph (their definitions:
#: docs/metrics.md).
LEGEND = ("quality: share of the truth's features the map has (the paper's q = matched truth / "
          "truth); precision: share of the map's features that are in the truth (matched map / "
          "map); f1: their harmonic mean; n/a: nothing to count; pair: a matched truth feature "
          "and map feature; displacement: the length from a pair's truth feature to its map "
          "feature; accuracy: distance from the map's walls to the truth's (their cells on the "
          "truth's grid, in the plan; 3D: between voxel centroids); completeness: from "
          "the truth's walls to the map's; F@tau: F-score of the walls within tau; noref: the "
          "input's own figures without a ground truth, as 'pcmapq inspect' gives them (lower "
          "is better, between maps of one place only); definitions in docs/metrics.md")


def score(value: float | None, digits: int = 3) -> str:
    """A quality, precision or f1 with ``digits`` decimals; 'n/a' when undefined (nothing to
    count, see :mod:`pcmapq.match.one_to_one`)."""
    return "n/a" if value is None else f"{value:.{digits}f}"


def number(value: float | None, digits: int = 3) -> str:
    """A figure with ``digits`` decimals; '-' when there is none (nothing measured)."""
    return "-" if value is None else f"{value:.{digits}f}"


def metres(value: float | None, digits: int = 3) -> str:
    """A length in metres, 'x.xxx m'; '-' when there is none (nothing measured)."""
    return "-" if value is None else f"{value:.{digits}f} m"


def map_3d_parts(figures: MapGaussians, settings: dict | None) -> list[str]:
    """MapEval's AWD and SCS of two 3D clouds and the voxels they are over (their side from
    the result's ``settings``), as values: ``AWD 0.052 m``, ``SCS 0.412``, ``over 812 voxels
    of 3 m``."""
    voxel = ((settings or {}).get("map_3d") or {}).get("voxel")
    over = count(figures.voxels, "voxel") + ("" if voxel is None else f" of {voxel:g} m")
    return [f"AWD {metres(figures.awd_m)}", f"SCS {number(figures.scs)}", f"over {over}"]


def alignment_words(result: Result) -> str:
    """How the map was placed on the truth, in words: the method and the confidence that it
    shows the truth's place."""
    method = result.alignment.method
    confidence = result.overlap.confidence
    if method == "none":
        return "not aligned (--no-align: the map's frame taken as the truth's)"
    if method == "init":
        placed = "placed at --init"
    elif method == "init+icp":
        placed = "aligned from --init"
    elif method == "3d+init":
        placed = "registered in 3D from --init-3d"
    elif method.startswith("similarity"):
        placed = f"aligned at an estimated scale of {result.transform.scale:.4f}"
    else:
        placed = "aligned"
    cover = result.overlap
    if cover.verdict == INCONSISTENT:
        # imported here: same_place loads the alignment, which reading a result does not need
        from pcmapq.evaluation.same_place import MIN_AGREEING

        agree = sum(p.agrees for p in cover.parts)
        why = (f"{agree} of its {count(len(cover.parts), 'part')} placed on their own land near "
               "its pose")
        if agree < MIN_AGREEING:  # the pose stands out: see same_place.verdict
            why = (f"its pose stands out in the search by "
                   f"{result.alignment.distinctiveness:.2f}; {why}")
        return (f"{placed}: a map of the truth's place that no single pose fits (confidence "
                f"{confidence:.2f}; {why}){breaks(result)}")
    if cover.verdict == LOW:
        poses = "; ".join(f"({tf.tx:.2f} m, {tf.ty:.2f} m, {tf.yaw_deg:.1f} deg), support "
                          f"{score:.2f}" for tf, score in result.alignment.poses)
        through = cover.seen_through or 0.0
        return (f"{placed} with low confidence ({confidence:.2f}): no pose stands out, yet "
                f"nothing refutes this one (it saw through {through:.0%} of the truth's walls "
                f"there); the two best poses: {poses}{breaks(result)}")
    if cover.verdict == OTHER:
        return (f"{placed}, but it may show another place (confidence {confidence:.2f} < 0.5, "
                "scored because of --force)")
    return f"{placed} with confidence {confidence:.2f}"


def breaks(result: Result) -> str:
    """Where the map breaks, as a clause: its region with the largest held offset (see
    :mod:`pcmapq.align.regions`), metres, truth frame; '' without one."""
    c = result.consistency
    k = None if c is None else c.largest()
    if k is None:
        return ""
    x, y = c.centre[k]
    return (f"; it breaks most at ({x:.1f}, {y:.1f}) m, where a region fits the truth moved "
            f"by {c.offset_m[k]:.2f} m and turned by {abs(c.turn_deg[k]):.1f} deg")


def relief_parts(result: Result) -> list[str]:
    """Two 3D clouds' 3D consistency map (:mod:`pcmapq.align.regions3d`) in short parts: the
    held regions' longest offset and largest vertical offset and where (truth frame levelled,
    metres; a stretch of the run's scans), and how many regions are held; [] without one."""
    c = result.consistency_3d
    if c is None:
        return []
    def at(k: int) -> str:
        span = c.scan_span(k)
        return (f"({c.centre[k, 0]:.1f}, {c.centre[k, 1]:.1f}, {c.centre[k, 2]:.1f}) m"
                + (f", {span}" if span else ""))

    parts = []
    if (k := c.largest()) is not None:
        parts.append(f"largest offset {c.offset_m[k]:.3f} m at {at(k)}")
    if (k := c.largest_dz()) is not None:
        dz = c.offset[k, 2]
        parts.append(f"largest dz {dz:+.3f} m ({'too low' if dz < 0 else 'too high'}) at "
                     f"{at(k)}")
    return [*parts, f"{int(c.held.sum())} of {count(len(c.points), 'region')} of "
                    f"{c.cut()} held"]


def verdict(result: Result) -> str:
    """How good the map is and why, in one sentence built from the result only: how it was
    aligned, how much of the truth it covers, each detector's quality and precision (a map
    full of features the truth lacks reads low; 'n/a' with why when undefined), and how far
    its walls are from the truth's, metres."""
    covered = f"{100 * result.overlap.coverage:.0f} % of the truth's walls covered"
    if result.full:
        covered += " (scored against the whole truth)"
    features = [_quality_precision(name, det.matching.quality, det.matching.precision,
                                   result.note(name))
                for name, det in result.detectors.items()]
    d = result.distances
    walls = (f"map walls {metres(d.accuracy.mean)} from the truth's on average, "
             f"truth walls {metres(d.completeness.mean)} from the map's")
    if d.accuracy.mean is None or d.completeness.mean is None:
        walls += " ('-': nothing to measure)"
    parts = [alignment_words(result), covered]
    if features:
        parts.append("feature quality/precision " + ", ".join(features))
    if result.structures is not None:
        parts.append("3D structure quality/precision " + ", ".join(
            _quality_precision(name, found.matching.quality, found.matching.precision,
                               found.matching.note(NOUNS[name]))
            for name, found in result.structures.detectors.items()))
    return f"{result.map_path.name}: " + "; ".join(parts + [walls]) + "."


def _quality_precision(name: str, quality: float | None, precision: float | None,
                       note: str | None) -> str:
    """A detector in the verdict: ``harris 0.97/0.82`` (quality/precision), ``n/a`` for an
    undefined one and why (``rooms n/a (the truth has 1 room ...)``)."""
    if quality is None and precision is None:
        return f"{name} n/a ({note})"
    pair = f"{name} {score(quality, 2)}/{score(precision, 2)}"
    return f"{pair} ({note})" if note else pair


def wrap(parts: Sequence[str], width: int, sep: str = ", ", indent: str = "") -> list[str]:
    """``parts`` joined by ``sep`` in lines of at most ``width`` characters, broken only between
    parts (a part longer than a line stands alone on its line); every line after the first
    starts with ``indent``."""
    lines: list[str] = []
    line = ""
    for i, part in enumerate(parts):
        piece = part + (sep.rstrip() if i < len(parts) - 1 else "")
        if line and len(line) + 1 + len(piece) > width:
            lines.append(line)
            line = indent + piece
        else:
            line = f"{line} {piece}" if line else piece
    return lines + ([line] if line else [])


def words(text: str, width: int, indent: str = "") -> list[str]:
    """``text`` wrapped at spaces in lines of at most ``width`` characters, a number never
    parted from its unit ('0.127 m', '97 %', '36.99 deg')."""
    glued = re.sub(r"(\d) (m|%|deg)(?!\w)", "\\1\u00a0\\2", text)
    return [line.replace("\u00a0", " ") for line in wrap(glued.split(" "), width, " ", indent)]
