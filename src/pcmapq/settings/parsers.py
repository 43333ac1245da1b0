"""The option table's readers and showers: an option's text as the setting it gives (refused
in one line naming the option, :class:`OptionError`), and a setting as the text that gives it."""

from __future__ import annotations

import math

import numpy as np

from pcmapq.core.errors import InputError
from pcmapq.core.transform import Similarity2D
from pcmapq.features.names import DETECTOR_NAMES
from pcmapq.raster.rules import FOOTPRINT_RULES


class OptionError(InputError):
    """An option's value that cannot be read: one line, naming the option (exit 2)."""

    def __init__(self, message: str, option: str) -> None:
        super().__init__(message)
        self.message, self.option = message, option


def parse_init(text: str) -> Similarity2D:
    """``x,y,yaw`` (metres, metres, degrees; finite) as a map -> truth guess."""
    try:
        x, y, yaw = (float(v) for v in text.split(","))
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(text)
    except ValueError:
        raise OptionError(f"expected finite x,y,yaw (metres, metres, degrees), got {text!r}",
                          "--init") from None
    return Similarity2D(x, y, float(np.radians(yaw)))


def show_init(tf: Similarity2D | None) -> str | None:
    return None if tf is None else f"{tf.tx:g},{tf.ty:g},{np.degrees(tf.yaw):g}"


#: How far a given 3D start's 3x3 part may be from a rotation (largest entry of R^T R - I,
#: and |det R - 1|): the rounding of a matrix written with a few decimals.
ROTATION_TOLERANCE = 1e-4
#: The rigid start ``--init-3d identity`` gives.
IDENTITY_3D = tuple(float(v) for v in np.eye(4).ravel())


def parse_init_3d(text: str) -> tuple[float, ...]:
    """A 4x4 rigid map -> truth transform, row-major (16 floats, metres), from ``identity``,
    16 comma-separated numbers (CloudAnalyzer's ``--initial-matrix``) or the path of a text
    file of its rows (as ``--transform`` writes it, CloudCompare's transformation file); 12
    numbers are its first three rows (a KITTI pose). Its 3x3 part, a rotation to within
    ROTATION_TOLERANCE, is made one exactly (:func:`_orthonormal`)."""
    if text.strip() == "identity":
        return IDENTITY_3D
    given = "," in text
    if given:
        values, what = text.split(","), f"got {text!r}"
    else:
        try:
            with open(text, encoding="utf-8") as f:
                values, what = f.read().split(), f"{text} holds something else"
        except (OSError, UnicodeDecodeError) as err:
            reason = getattr(err, "strerror", None) or "not a text file"
            raise OptionError(f"{text}: {reason.lower()}; expected identity, 16 comma-separated "
                              "numbers or a file of a 4x4 matrix", "--init-3d") from None
    try:
        numbers = np.array([float(v) for v in values])
        if len(numbers) not in (12, 16) or not np.isfinite(numbers).all():
            raise ValueError(text)
    except ValueError:
        raise OptionError("expected a 4x4 rigid transform, row by row: 16 finite numbers (or "
                          f"the 12 of its first three rows); {what}", "--init-3d") from None
    if len(numbers) == 12:  # the first three rows
        numbers = np.append(numbers, [0.0, 0.0, 0.0, 1.0])
    matrix = numbers.reshape(4, 4)
    rotation = matrix[:3, :3]
    off = max(float(np.abs(rotation.T @ rotation - np.eye(3)).max()),
              abs(float(np.linalg.det(rotation)) - 1.0))
    if off > ROTATION_TOLERANCE or not np.array_equal(matrix[3], [0.0, 0.0, 0.0, 1.0]):
        raise OptionError(f"{'the matrix' if given else text}: not a rigid transform (its 3x3 "
                          "part is no rotation, or its last row is not 0 0 0 1)", "--init-3d")
    matrix[:3, :3] = _orthonormal(rotation.tolist())
    return tuple(float(v) + 0.0 for v in matrix.ravel())


def _orthonormal(rows: list[list[float]]) -> list[list[float]]:
    """A rotation made of a 3x3 matrix near one: its first row normalised, its second made
    orthogonal to it and normalised (Gram-Schmidt), the third their cross product; in Python
    floats, so the same bits whatever the machine and wherever its arrays lie."""
    x, y = rows[0], rows[1]
    length = math.sqrt(sum(v * v for v in x))
    x = [v / length for v in x]
    along = sum(a * b for a, b in zip(x, y, strict=True))
    y = [b - along * a for a, b in zip(x, y, strict=True)]
    length = math.sqrt(sum(v * v for v in y))
    y = [v / length for v in y]
    return [x, y, [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                   x[0] * y[1] - x[1] * y[0]]]


def show_init_3d(matrix: tuple[float, ...] | None) -> str | None:
    if matrix is None:
        return None
    return "identity" if tuple(matrix) == IDENTITY_3D else ",".join(repr(v) for v in matrix)


def parse_box(text: str, option: str) -> tuple[float, float, float, float]:
    """A box ``x0,y0,x1,y1`` (metres, finite, x0 < x1, y0 < y1)."""
    try:
        x0, y0, x1, y1 = (float(v) for v in text.split(","))
        if not (all(math.isfinite(v) for v in (x0, y0, x1, y1)) and x0 < x1 and y0 < y1):
            raise ValueError(text)
    except ValueError:
        raise OptionError(f"expected a box x0,y0,x1,y1 in metres with x0 < x1 and y0 < y1, got "
                          f"{text!r}", option) from None
    return x0, y0, x1, y1


def show_list(values: tuple | None) -> str | None:
    return None if values is None else ",".join(f"{v:g}" if isinstance(v, float) else str(v)
                                                for v in values)


def parse_map_resolution(text: str) -> float | None:
    """Metres per pixel, or ``auto`` (None: the scale is estimated)."""
    if text == "auto":
        return None
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 < value < math.inf:
        raise OptionError(f"expected metres per pixel or 'auto', got {text!r}",
                          "--map-resolution")
    return value


def parse_scale(text: str) -> bool:
    if text not in ("fixed", "auto"):
        raise OptionError(f"expected 'fixed' or 'auto', got {text!r}", "--scale")
    return text == "auto"


def parse_taus(text: str) -> tuple[float, ...]:
    """Positive finite distances, metres, comma-separated."""
    try:
        taus = tuple(float(v) for v in text.split(","))
    except ValueError:
        taus = ()
    if not taus or not all(0 < t < math.inf for t in taus):
        raise OptionError(f"expected positive finite distances in metres, got {text!r}",
                          "--tau")
    return taus


def parse_detectors(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    unknown = [n for n in names if n not in DETECTOR_NAMES]
    if unknown or not names:
        raise OptionError(f"unknown detector(s) {unknown}; choose from "
                          f"{','.join(DETECTOR_NAMES)}", "--detectors")
    return names


def parse_footprint(text: str) -> str:
    if text not in FOOTPRINT_RULES:
        raise OptionError(f"expected one of {', '.join(FOOTPRINT_RULES)}, got {text!r}",
                          "--footprint")
    return text
