"""Stored references (``tests/reference/``): the figures a result's JSON document keeps for the
validation's cases (``tests/reference/validation/<case>.json``, written and checked by
``python -m bench.validation``), and the comparison of two JSON documents (numbers within 1e-6)
that tests use for the sample's reference too."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .paths import REFERENCES, REPO

if TYPE_CHECKING:
    from pcmapq.results.result import Result

FOLDER = REFERENCES / "validation"

_STATS = ("mean", "median")
_DISTANCES = {"accuracy_m": _STATS, "completeness_m": _STATS, "chamfer_m": None, "f_score": None}
_STRUCTURES = ("quality", "precision", "f1", "truth_structures", "map_structures", "matched")
#: The fields of ``Result.to_dict()`` a reference keeps: a tuple names the keys kept of a dict,
#: None keeps the whole value, ``"*"`` applies its spec to every entry; absent keys are skipped.
FIELDS: dict[str, Any] = {
    "alignment": ("x_m", "y_m", "yaw_deg", "scale", "fitness", "rmse_m", "truth_recall",
                  "agreement", "distinctiveness", "confidence"),
    "coverage": None,
    "footprint": None,
    "distances": _DISTANCES,
    "alignment_3d": ("matrix", "fitness", "rmse_m"),
    "distances_3d": _DISTANCES,
    "detectors": {"*": ("quality", "precision", "f1", "truth_features", "map_features",
                        "matched")},
    "structures_3d": {name: _STRUCTURES for name in ("planes", "plane_lines")},
}


def _pick(value: Any, spec: Any) -> Any:
    """The part of ``value`` that ``spec`` names (see :data:`FIELDS`)."""
    if spec is None:
        return value
    if isinstance(spec, tuple):
        return {key: value[key] for key in spec}
    if "*" in spec:
        return {key: _pick(item, spec["*"]) for key, item in value.items()}
    return {key: _pick(value[key], sub) for key, sub in spec.items() if key in value}


def summary(doc: dict) -> dict:
    """The figures of a result's JSON document (``Result.to_dict()``) that its reference keeps:
    new fields of the document do not change it."""
    return _pick(doc, FIELDS)


#: Numbers differ when more than this apart: saved numbers are rounded to 6 decimals, and a
#: library's last-bit change in a figure can move one of them by a unit of the 6th decimal.
TOLERANCE = 1.5e-6


def differences(got: Any, want: Any, where: str = "", tol: float = TOLERANCE) -> list[str]:
    """Where two JSON values differ: keys of the reference that are gone, lengths, strings, or
    numbers by more than ``tol``. Keys the reference does not have are new fields, not changes."""
    if isinstance(want, dict) and isinstance(got, dict):
        if set(want) - set(got):
            return [f"{where}: keys {sorted(set(want) - set(got))} gone"]
        return [d for k in want for d in differences(got[k], want[k], f"{where}.{k}", tol)]
    if isinstance(want, list) and isinstance(got, list):
        if len(got) != len(want):
            return [f"{where}: {len(got)} items, reference {len(want)}"]
        return [d for i, (g, w) in enumerate(zip(got, want, strict=True))
                for d in differences(g, w, f"{where}[{i}]", tol)]
    numbers = (int, float)
    if (isinstance(got, numbers) and isinstance(want, numbers)
            and not isinstance(got, bool) and not isinstance(want, bool)):
        return [] if abs(got - want) <= tol else [f"{where}: {got} != {want}"]
    return [] if got == want else [f"{where}: {got!r} != {want!r}"]


def path(case: str) -> Path:
    """The reference file of a case."""
    return FOLDER / f"{case}.json"


def store(record: dict[str, dict]) -> None:
    """Write the reference of every case of ``record`` (by hand, after a change meant to move
    the figures; say why in the commit)."""
    FOLDER.mkdir(parents=True, exist_ok=True)
    for case, figures in record.items():
        path(case).write_text(json.dumps(figures, indent=1) + "\n")


def compare(case: str, figures: dict) -> list[str]:
    """How a case's figures differ from its stored reference (``case: ...`` lines)."""
    file = path(case)
    if not file.is_file():
        return [f"{case}: no reference ({file.relative_to(REPO)})"]
    return [f"{case}{d}" for d in differences(json.loads(json.dumps(figures)),
                                              json.loads(file.read_text()))]


def same_document(back: Result, original: Result) -> list[str]:
    """Where two results' JSON documents differ: every key and string alike, every number
    within what the JSON's rounding to 1e-6 allows for figures derived from rounded ones
    (displacements from rounded positions: 1e-5; the pose, the tilt and the 3D structures'
    fit from a rounded matrix: 1e-4)."""
    got, want = back.to_dict(), original.to_dict()
    assert set(got) == set(want)

    def positions(doc: dict) -> dict:
        out = {k: doc[k] for k in doc if k not in ("alignment", "frames")}
        if isinstance(out.get("structures_3d"), dict):
            out["structures_3d"] = {k: v for k, v in out["structures_3d"].items() if k != "fit"}
        return out

    return differences(got, want, tol=1e-4) + differences(positions(got), positions(want),
                                                          tol=1e-5)
