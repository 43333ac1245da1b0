"""Stats: the one summary of a set of lengths that every figure of pcmapq uses (feature
displacements, map-to-truth and truth-to-map distances, in 2D and 3D), metres."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

#: The fields, in the order the JSON, the table and the report show them.
FIELDS = ("count", "mean", "median", "rmse", "std", "min", "max", "p95")


@dataclass(frozen=True)
class Stats:
    """count, mean, median, RMSE, standard deviation (population, ddof 0), min, max and 95th
    percentile (linear interpolation) of a set of lengths, in their unit (metres). Every figure
    but ``count`` is None when the set is empty or holds an infinite length (nothing on the
    other side to measure to): undefined, not 0."""

    count: int
    mean: float | None = None
    median: float | None = None
    rmse: float | None = None
    std: float | None = None
    min: float | None = None
    max: float | None = None
    p95: float | None = None

    @classmethod
    def of(cls, values: np.ndarray) -> Stats:
        """The statistics of ``values`` (N,), any shape flattened."""
        d = np.asarray(values, dtype=np.float64).ravel()
        if len(d) == 0 or not np.isfinite(d).all():
            return cls(int(len(d)))
        return cls(int(len(d)), float(d.mean()), float(np.median(d)),
                   float(np.sqrt(np.mean(d**2))), float(d.std()), float(d.min()),
                   float(d.max()), float(np.percentile(d, 95)))

    def to_dict(self) -> dict[str, int | float | None]:
        """The fields by name, in :data:`FIELDS` order."""
        return asdict(self)

    @classmethod
    def from_dict(cls, doc: dict) -> Stats:
        """The inverse of :meth:`to_dict`."""
        return cls(**{k: doc[k] for k in FIELDS})


def significant(value: Any, digits: int = 6) -> Any:
    """Every float of a nested structure (dicts, lists) rounded to ``digits`` decimals, or to
    ``digits`` significant digits where that keeps more: the JSON form of figures whose scale
    varies (MME in nats near -3.6 keeps 6 decimals; MPV and MOM, areas of 1e-3 m^2 and less,
    keep 6 significant digits where 6 decimals would keep one)."""
    if isinstance(value, float):
        if value == 0.0 or not math.isfinite(value):
            return value + 0.0
        return round(value, max(digits, digits - 1 - math.floor(math.log10(abs(value))))) + 0.0
    if isinstance(value, dict):
        return {k: significant(v, digits) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [significant(v, digits) for v in value]
    return value
