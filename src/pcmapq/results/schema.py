"""The result's JSON document, declared once: :meth:`Result.to_dict` writes these models and
:meth:`Result.from_json` reads them, and docs/result.schema.json is generated from them. Truth
frame, metres and degrees. A key that may be absent has a default (a field left unset is not
written); every other key is always written, null where undefined."""

from __future__ import annotations

import json
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError

from pcmapq.core.stats import Stats
from pcmapq.metrics.distances import FScore
from pcmapq.results.structures_schema import Structures3D

Point = tuple[float, float]
Matrix = list[list[float]]


class Block(BaseModel):
    """A block of the document: its keys are exactly its fields, in their order."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)


class Producer(Block):
    """What wrote the document."""

    version: str
    """pcmapq's version."""
    command: str | None
    """The command line that made it, defaults left out; null from the library."""


class MapInput(Block):
    """The map's file, and for a map read from a recording which of its messages."""

    path: str
    kind: str
    """How it was read: image, cloud, bag, carmen, ..."""
    topic: str | None = None
    """The recording's topic the map was read from."""
    index: int | None = None
    """The message's index among the topic's messages, from 0 in time order."""
    time_s: float | None = None
    """When the message was recorded: seconds from the recording's first message."""
    stamp_s: float | None = None
    """The message header's stamp, seconds of the clock it was stamped with."""


class Origin(Block):
    """Where the truth's grid starts: its lower-left corner in the truth frame."""

    x_m: float
    y_m: float
    yaw_deg: float


class TruthInput(Block):
    """The truth's file and the grid every raster of the result lies on."""

    path: str
    kind: str
    resolution_m: float
    """A cell's side."""
    origin: Origin
    shape: tuple[int, int]
    """Rows and columns of the grid."""
    sha256: str | None = None
    """The truth file's SHA-256 (hex), so results of one truth are known as such."""


class Pose(Block):
    """A map -> truth transform in the plane: ``p_truth = s * R(yaw) * p_map + t``."""

    x_m: float
    y_m: float
    yaw_deg: float
    scale: float


class ScoredPose(Pose):
    """A pose the global search found, with its score."""

    score: float


class PartPlaced(Block):
    """One part of the map placed on its own."""

    share: float
    """Its share of the map's points."""
    centre_m: Point
    """Its centroid where the map's pose puts it."""
    offset_m: float
    """How far its own pose puts that centroid from there."""
    turn_deg: float
    """How far its own pose turns it from the map's pose, in [0, 180]."""
    fitness: float
    agrees: bool
    """Within the agreement bounds."""
    pose: Pose
    """Its own map -> truth transform."""


class Alignment(Pose):
    """The map's pose on the truth and how sure it is (docs/metrics.md)."""

    matrix: Matrix
    """The pose as a 3 x 3 homogeneous matrix."""
    fitness: float
    rmse_m: float
    tolerance_m: float
    method: str
    truth_recall: float
    seen_through: float | None = None
    """Share of the truth's walls in the footprint lying on the map's free space; null for a
    map without free space."""
    agreement: float
    distinctiveness: float | None
    contradiction: float | None = None
    free_on_truth: float | None = None
    poses: list[ScoredPose] = []
    """The global search's best poses, best first."""
    confidence: float
    """That one pose places the map on the truth's place, [0, 1]."""
    verdict: str
    """"same place", "same place, inconsistent map", "placed with low confidence" or
    "another place"."""
    parts: list[PartPlaced]


class Region(Block):
    """One region of the consistency map, aligned on its own."""

    x_m: float
    y_m: float
    dx_m: float
    dy_m: float
    offset_m: float
    turn_deg: float
    points: int
    fitness_before: float
    fitness_after: float
    held: bool
    """Its walls hold it in both directions (its offset is sure)."""


class ConsistencyMap(Block):
    """The map cut into tiles, each aligned to the truth on its own (all null and no region
    when not made)."""

    tile_m: float | None
    largest_offset_m: float | None
    largest_at_m: Point | None
    global_fitness: float | None
    local_fitness: float | None
    regions: list[Region]


class Levelling(Block):
    """A 3D cloud's levelling: the rotation that makes its floor horizontal."""

    matrix: Matrix
    tilt_deg: float
    floor_z_m: float


class Frames(Block):
    """The chain from each input to the truth's plan."""

    convention: str
    map_levelling: Levelling | None
    registration_3d: Matrix | None
    """The 4 x 4 map cloud -> truth cloud transform when both are 3D clouds."""
    planar: Pose
    truth_levelling: Levelling | None


class Distances(Block):
    """Distances between the two maps' walls (docs/metrics.md)."""

    computed_on: str = ""
    """What they were measured on: the grid's cells or the clouds' points."""
    accuracy_m: Stats
    """Map -> truth."""
    completeness_m: Stats
    """Truth -> map."""
    chamfer_m: float | None
    f_score: list[FScore]


class Detector(Block):
    """One detector's scores (the paper's quality q and more)."""

    quality: float | None
    precision: float | None
    f1: float | None
    note: str | None
    """Why a score is null."""
    truth_features: int
    map_features: int
    matched: int
    matched_map: int
    threshold_m: float
    displacement_m: Stats


class Counted(Block):
    """Which of a pair's features are counted (strong) rather than support-level."""

    truth: bool
    map: bool


class Match(Block):
    """A matched pair: one arrow of the vectorial map."""

    detector: str
    truth_xy_m: Point
    map_xy_m: Point
    displacement_m: float
    counted: Counted


class Missing(Block):
    """A truth feature the map lacks."""

    detector: str
    truth_xy_m: Point


class Extra(Block):
    """A map feature the truth lacks."""

    detector: str
    map_xy_m: Point


class Registration3D(Block):
    """The 3D registration of two clouds."""

    matrix: Matrix
    fitness: float
    rmse_m: float


class Gate(Block):
    """One gate (``--fail-under``, ``--fail-over``) judged on the result."""

    key: str
    path: str
    option: str
    bound: float
    value: float | None
    passed: bool


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
    structures_3d: Structures3D | None = None
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
