"""Settings as plain JSON types (:meth:`Settings.to_dict
<pcmapq.settings.configs.Settings.to_dict>`): dataclasses as objects, a pose in metres and
degrees, tuples as lists."""

from __future__ import annotations

from dataclasses import fields, is_dataclass
from typing import Any

from pcmapq.core.transform import Similarity2D


def plain(value: Any) -> Any:
    """A settings value as plain JSON types (see :meth:`Settings.to_dict`)."""
    if isinstance(value, Similarity2D):
        return value.to_dict()
    if is_dataclass(value):
        return {f.name: plain(getattr(value, f.name)) for f in fields(value)}
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, tuple):
        return [plain(v) for v in value]
    return value
