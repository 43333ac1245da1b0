"""evaluate(): the method in one screen. load -> prepare the truth -> place the map (align,
raster, same-place verdict) -> score (features, match, distances)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from pcmapq.evaluation.inputs import load_pair
from pcmapq.evaluation.noref_figures import EarlyFigures
from pcmapq.evaluation.placing import Progress, check_footprint_rule, place
from pcmapq.evaluation.scoring import score
from pcmapq.evaluation.truth import prepare_truth
from pcmapq.io import PointMap
from pcmapq.io.digest import sha256_file
from pcmapq.results.result import Result
from pcmapq.settings import Settings


def evaluate(map_path: str | Path | PointMap, truth_path: str | Path,
             settings: Settings | None = None, progress: Progress = lambda step: None,
             memory_limit: int | None = None, truth_sha256: str | None = None) -> Result:
    """Score the map at ``map_path`` (or a map already built, e.g. from scans) against the
    truth at ``truth_path``; stop (InputError) when the run would need more than
    ``memory_limit`` bytes (None: :func:`pcmapq.core.memory.default_limit`).
    ``truth_sha256``: the truth file's SHA-256 when the caller has it (a batch row's key),
    else read here. The truth's features, and the 3D clouds' no-reference figures, are found on
    threads of their own while the map is placed."""
    settings = Settings() if settings is None else settings
    progress("loading")
    source, truth = load_pair(map_path, truth_path, settings, memory_limit)
    check_footprint_rule(source, settings)  # a rule the map cannot follow: before any work
    prepared = prepare_truth(truth, settings, memory_limit, maps=(0,), loaded=(source,),
                             background=True)
    early = EarlyFigures({"map": source, "truth": truth}, settings)
    try:
        result = score(place(source, prepared, settings, progress, early.walls_found),
                       prepared, settings, progress, early)
    except BaseException:
        prepared.cancel()
        early.cancel()
        raise
    return replace(result, truth_sha256=truth_sha256 or sha256_file(truth_path))
