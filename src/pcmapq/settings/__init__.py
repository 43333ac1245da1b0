"""Settings: every option of a run in one object, nested by pipeline stage, every length in
metres. The groups and their defaults are in :mod:`~pcmapq.settings.configs`, the option table
that names each option once in :mod:`~pcmapq.settings.table`, the settings built from options
in :mod:`~pcmapq.settings.build`, settings files in :mod:`~pcmapq.settings.file`; this package
re-exports the names the rest of pcmapq uses."""

from __future__ import annotations

from pcmapq.features.names import DEFAULT_DETECTORS, DETECTOR_NAMES
from pcmapq.settings.configs import (
    EVAL_MAX_WARD,
    EVAL_NOREF_SAMPLE,
    EVAL_NOREF_VOXEL,
    MIN_HITS_2D,
    MIN_HITS_3D,
    TRACK_EVERY,
    AlignmentConfig,
    DistancesConfig,
    FootprintConfig,
    Map3DConfig,
    MatchingConfig,
    NoRefConfig,
    RasterConfig,
    Settings,
    SourceConfig,
    StructuresConfig,
    default_params,
)
from pcmapq.settings.plain import plain

__all__ = ["DEFAULT_DETECTORS", "DETECTOR_NAMES", "EVAL_MAX_WARD", "EVAL_NOREF_SAMPLE",
           "EVAL_NOREF_VOXEL", "MIN_HITS_2D", "MIN_HITS_3D", "TRACK_EVERY", "AlignmentConfig",
           "DistancesConfig", "FootprintConfig", "Map3DConfig", "MatchingConfig", "NoRefConfig",
           "RasterConfig", "Settings", "SourceConfig", "StructuresConfig", "default_params",
           "plain"]
