"""The result's JSON document, declared once: :meth:`Result.to_dict` writes these models and
:meth:`Result.from_json` reads them, and docs/result.schema.json is generated from them. Truth
frame, metres and degrees. A key that may be absent has a default (a field left unset is not
written); every other key is always written, null where undefined."""

from pcmapq.results.schema.base import Block, Matrix, Point, Point3
from pcmapq.results.schema.blocks import (
    Alignment,
    ConsistencyMap,
    Counted,
    Detector,
    Distances,
    Extra,
    Frames,
    Gate,
    Levelling,
    MapInput,
    Match,
    Missing,
    Origin,
    PartPlaced,
    Pose,
    Producer,
    Region,
    ScoredPose,
    TruthInput,
)
from pcmapq.results.schema.blocks_3d import (
    ConsistencyMap3D,
    Map3D,
    Region3D,
    Registration3D,
)
from pcmapq.results.schema.document import ResultDocument, json_schema, problem, schema_text

__all__ = ['Alignment', 'Block', 'ConsistencyMap', 'ConsistencyMap3D', 'Counted', 'Detector',
           'Distances', 'Extra', 'Frames', 'Gate', 'Levelling', 'Map3D', 'MapInput', 'Match',
           'Matrix', 'Missing', 'Origin', 'PartPlaced', 'Point', 'Point3', 'Pose', 'Producer',
           'Region', 'Region3D', 'Registration3D', 'ResultDocument', 'ScoredPose', 'TruthInput',
           'json_schema', 'problem', 'schema_text']
