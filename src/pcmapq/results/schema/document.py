"""The result's whole document, its JSON Schema (docs/result.schema.json) and a one-line
account of a document that strays from it."""

from __future__ import annotations

import json
from typing import Any

from pydantic import ValidationError

from pcmapq.results.schema.base import Block
from pcmapq.results.schema.blocks import (
    Alignment,
    ConsistencyMap,
    Detector,
    Distances,
    Extra,
    Frames,
    Gate,
    MapInput,
    Match,
    Missing,
    Producer,
    TruthInput,
)
from pcmapq.results.schema.blocks_3d import ConsistencyMap3D, Map3D, Registration3D
from pcmapq.results.schema.structures import Structures3D


class ResultDocument(Block):
    """What ``pcmapq eval --json`` writes: everything a run found."""

    pcmapq: Producer
    settings: dict[str, Any] | None
    """The options it ran with (docs/config.md)."""
    map: MapInput
    truth: TruthInput
    alignment: Alignment
    consistency: ConsistencyMap | None = None
    frames: Frames
    coverage: float
    footprint: str
    scored_against: str
    """"whole truth" or "footprint"."""
    distances: Distances
    noref: dict[str, Any] | None
    """Each input's no-reference figures, ``{"map": ..., "truth": ...}``."""
    detectors: dict[str, Detector]
    matches: list[Match]
    missing: list[Missing]
    extra: list[Extra]
    alignment_3d: Registration3D | None = None
    distances_3d: Distances | None = None
    map_3d: Map3D | None = None
    """Two 3D clouds in one frame: MapEval's AWD and SCS."""
    consistency_3d: ConsistencyMap3D | None = None
    """Only when both inputs are 3D clouds."""
    structures_3d: Structures3D | None = None
    """Two 3D clouds registered in 3D: their planes and plane lines, matched."""
    rooms: dict[str, Any] | None = None
    """The rooms detector's rooms and doors, each with its status."""
    gates: list[Gate] | None = None


def json_schema() -> dict[str, Any]:
    """The document's JSON Schema (draft 2020-12), as published in docs/result.schema.json."""
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            **_untitled(ResultDocument.model_json_schema(mode="serialization"))}


def _untitled(node: Any) -> Any:
    """``node`` without the titles pydantic makes of field names (``"X M"``)."""
    if isinstance(node, dict):
        return {k: _untitled(v) for k, v in node.items()
                if not (k == "title" and isinstance(v, str) and "properties" not in node)}
    if isinstance(node, list):
        return [_untitled(v) for v in node]
    return node


def schema_text() -> str:
    """:func:`json_schema` as docs/result.schema.json holds it."""
    return json.dumps(json_schema(), indent=2) + "\n"


def problem(error: ValidationError) -> str:
    """A document's departure from the schema in one line: the shallowest one (a missing
    group before the keys inside it), where and what, and how many more there are."""
    first = min(error.errors(), key=lambda e: len(e["loc"]))
    where = ".".join(str(k) for k in first["loc"]) or "the document"
    more = error.error_count() - 1
    what = f"no '{where}'" if first["type"] == "missing" else f"{where}: {first['msg']}"
    return what + (f" (and {more} more)" if more else "")
